#!/usr/bin/env bash
# The viscous rates' growing modes (docs/validation.md, "The viscous rates' spectrum"): on the ring of
# 30,000 particles at tau = 0.018 the linear gradient correction's rates have an eigenvalue of real
# part ~ +0.88 nu / h_min^2 (a close pair moving apart), the mixed correction's none above ~0.05.
# Fails if the mixed correction's largest real part reaches 0.2 nu / h_min^2 (the growing modes are
# back) or if the linear one's falls below 0.5 (then this ring no longer shows what the check is for).
# Usage: viscous_spectrum_modes.sh VISCOUS_SPECTRUM_EXE
set -uo pipefail
source "$(dirname "$0")/../lib/checks.sh"
exe=$1
largest_real_part() {
  "$exe" --particles 30000 --iterations 150 --gradient-correction "$1" | sed -n 's/.*largest real part \([-0-9.e+]*\) .*/\1/p'
}
mixed=$(largest_real_part mixed)
linear=$(largest_real_part linear)
echo "largest real part (nu / h_min^2): mixed $mixed, linear $linear"
if awk -v x="$mixed" 'BEGIN { exit !(x != "" && x < 0.2) }'; then ok "mixed correction: no growing mode ($mixed < 0.2)"
else bad "mixed correction: largest real part $mixed, not < 0.2"; fi
if awk -v x="$linear" 'BEGIN { exit !(x != "" && x > 0.5) }'; then ok "linear correction: the growing mode is there ($linear > 0.5)"
else bad "linear correction: largest real part $linear, not > 0.5"; fi
finish "viscous_spectrum_modes: "
