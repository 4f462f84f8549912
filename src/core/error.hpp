#pragma once
// Errors a user can fix (bad configuration, bad input files, unwritable output). The driver prints
// what() as one line on stderr and exits non-zero; no stack trace, no partial output.
#include <stdexcept>
#include <string>

namespace sphdisk {

class UserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A run that went wrong numerically (NaN, Inf): reported with particle, field and step.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An error another MPI rank has already reported (this rank stops quietly with the same code).
class PeerError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Messages are one line: control characters (e.g. a newline quoted from a bad input) are escaped.
inline std::string one_line(const std::string& s) {
  std::string out;
  for (const char ch : s) {
    const auto u = static_cast<unsigned char>(ch);
    if (u >= 0x20 && u != 0x7f) {
      out += ch;
      continue;
    }
    static const char* hex = "0123456789abcdef";
    out += ch == '\n' ? std::string("\\n") : ch == '\t' ? std::string("\\t") : std::string("\\x") + hex[u >> 4] + hex[u & 15];
  }
  return out;
}

}  // namespace sphdisk
