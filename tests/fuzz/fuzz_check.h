// FUZZ_CHECK: the harnesses' oracle. A failed check prints what was expected
// and aborts, which libFuzzer reports as a crash and saves the input as a
// reproducer (the sanitizers catch memory errors and undefined behaviour; these
// checks catch wrong answers that are not memory errors).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

#include "absl/status/status.h"

namespace surfmap::fuzz {

[[noreturn]] inline void FailCheck(const char* file, int line, const char* condition, const std::string& detail) {
  std::fprintf(stderr, "%s:%d: FUZZ_CHECK failed: %s\n  %s\n", file, line, condition, detail.c_str());
  std::abort();
}

inline std::string Describe(const absl::Status& status) { return status.ToString(); }

}  // namespace surfmap::fuzz

#define FUZZ_CHECK(condition, detail)                                              \
  do {                                                                             \
    if (!(condition)) ::surfmap::fuzz::FailCheck(__FILE__, __LINE__, #condition, (detail)); \
  } while (0)
