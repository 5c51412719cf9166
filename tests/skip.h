// Skipping a test case whose dependency is missing on this machine (ffmpeg, a GL backend).
#pragma once

#include <catch2/catch.hpp>

/// The marker ctest looks for: every test of tests/CMakeLists.txt that prints it is reported
/// SKIPPED (SKIP_REGULAR_EXPRESSION), never passed.
#define CPS_SKIP_MARKER "cps test skipped:"

/// Ends the current test case as skipped, saying why (what is missing and how to install it).
/// Use it before the case has checked anything: ctest reports a case that printed the marker as
/// skipped whatever its checks did. `why` is anything Catch2's WARN takes (a stream expression).
#define CPS_SKIP(why)                          \
  do {                                         \
    WARN(CPS_SKIP_MARKER " " << why);          \
    return;                                    \
  } while (false)
