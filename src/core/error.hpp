// Errors: every failure lodstream reports to a user is an lodstream::Error whose message is one line that
// names what is wrong and where (a file, a byte offset, an argument). The command line prints it as
// "lodstream: error: <message>" and exits 1.
#pragma once

#include <stdexcept>
#include <string>

namespace lodstream {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace lodstream
