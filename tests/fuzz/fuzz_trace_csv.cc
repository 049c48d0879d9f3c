// libFuzzer harness: drag-trace CSV text -> ParseTraceCsv -> FitTrace.
//
// Checks beyond the sanitizers: a rejection is INVALID_ARGUMENT with the
// "<source>:<line>: " prefix the reader promises; an accepted trace survives
// FormatTraceCsv -> ParseTraceCsv bit for bit (the documented round trip, which
// the CLI's trace export relies on) and is then fitted (trace_fit_check.h).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "server/estimate/trace_csv.h"
#include "tests/fuzz/fuzz_check.h"
#include "tests/fuzz/trace_fit_check.h"

namespace {

// Keeps every input fast: the example traces are ~70 KB (515 samples), and a
// longer text only repeats lines the reader already handles.
constexpr std::size_t kMaxInputBytes = 128 * 1024;
constexpr std::string_view kSource = "fuzz.csv";
constexpr std::string_view kMessagePrefix = "fuzz.csv:";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace surfmap;
  if (size > kMaxInputBytes) return -1;  // -1: not added to the corpus
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const absl::StatusOr<DragTrace> trace = ParseTraceCsv(text, kSource);
  if (!trace.ok()) {
    FUZZ_CHECK(trace.status().code() == absl::StatusCode::kInvalidArgument, fuzz::Describe(trace.status()));
    const std::string_view message(trace.status().message().data(), trace.status().message().size());
    FUZZ_CHECK(message.starts_with(kMessagePrefix), fuzz::Describe(trace.status()));
    return 0;
  }
  FUZZ_CHECK(!trace->samples.empty(), "accepted a trace without samples");

  const std::string written = FormatTraceCsv(*trace);
  const absl::StatusOr<DragTrace> reread = ParseTraceCsv(written, "round trip");
  FUZZ_CHECK(reread.ok(), absl::StrCat("FormatTraceCsv output does not read back: ", fuzz::Describe(reread.status())));
  FUZZ_CHECK(fuzz::SameTrace(*trace, *reread), "FormatTraceCsv -> ParseTraceCsv changed a value");

  fuzz::FitAndCheck(*trace);
  return 0;
}
