// SPDX-License-Identifier: MIT
// check.hpp: the non-fatal check of the small C++ test programs that run one sequence of
// steps against a port module or a tool library (the cmocka suites are the unit tests).
// CHECK(cond) prints file:line and the condition on stderr, counts a failure in
// sl_test::failures and goes on; the program returns non-zero when any check failed.
#pragma once

#include <iostream>

namespace sl_test {
inline int failures = 0;
} // namespace sl_test

#define CHECK(cond)                                                                          \
    do {                                                                                     \
        if (!(cond)) {                                                                       \
            std::cerr << __FILE__ << ":" << __LINE__ << ": CHECK failed: " #cond "\n";       \
            ::sl_test::failures++;                                                           \
        }                                                                                    \
    } while (0)
