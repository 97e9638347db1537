#pragma once
// Typed errors. Every message should let a user act: name the file or
// parameter and the problem, with numbers where there are numbers.
#include <stdexcept>
#include <string>

namespace tessera {

// Base of all Tessera errors.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A file or user argument is malformed, inconsistent or unsupported.
class InputError : public Error {
 public:
  using Error::Error;
};

// A host or GPU memory budget would be exceeded.
class BudgetError : public Error {
 public:
  using Error::Error;
};

// The GL/EGL driver failed or lacks something we need.
class GpuError : public Error {
 public:
  using Error::Error;
};

}  // namespace tessera
