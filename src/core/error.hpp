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

}  // namespace sphdisk
