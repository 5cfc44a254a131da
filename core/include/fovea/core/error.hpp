#pragma once
// Errors caused by bad input (files, configs, arguments, device reports). The command
// line turns them into a message naming the input and exit code 2.
#include <stdexcept>
#include <string>

namespace fovea::core {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace fovea::core
