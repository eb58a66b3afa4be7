// Checks the one-line errors of bad input: `f()` must throw lodstream::Error whose message starts with
// `where` (the input the error names first); `what` names the case in a failure.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "core/error.hpp"

namespace lodstream::test {

template <class F>
void expect_error_naming(const std::string& where, const char* what, F&& f) {
  try {
    f();
    ADD_FAILURE() << what << ": no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(where, 0), 0u) << what << ": " << e.what();
  }
}

}  // namespace lodstream::test
