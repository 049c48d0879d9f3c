// libFuzzer harness: SubmitTraceRequest wire bytes (what a rig sends) ->
// DragTraceFromProto -> FitTrace.
//
// Checks beyond the sanitizers: a rejection is INVALID_ARGUMENT or (too many
// samples) RESOURCE_EXHAUSTED; an accepted trace survives DragTraceToProto ->
// DragTraceFromProto bit for bit; it is fitted (trace_fit_check.h); and a
// trace FitTrace accepts is one the CSV reader accepts too, written by
// FormatTraceCsv and read back unchanged (the CLI exports stored traces as
// CSV, and a trace the server fitted must be one a user can re-read).
//
// Structure-aware: the custom mutator below edits decoded requests row by row
// (insert, delete, duplicate, perturb one value, change a phase) half of the
// time. Byte mutations alone mostly break the packed columns' length prefixes
// or make the columns unequal, which DragTraceFromProto rejects at once.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include <google/protobuf/stubs/logging.h>
#include "absl/strings/str_cat.h"
#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/codec/trace_samples_proto.h"
#include "server/estimate/trace_csv.h"
#include "tests/fuzz/fuzz_check.h"
#include "tests/fuzz/trace_fit_check.h"

namespace {

namespace pb = ::surfmap::v1;

// A 4096-sample trace is ~230 KB on the wire; the limit on conversion is the
// fitting limit, so RESOURCE_EXHAUSTED is exercised too.
constexpr std::size_t kMaxInputBytes = 256 * 1024;
constexpr int kMaxSamples = static_cast<int>(surfmap::fuzz::kMaxFittedSamples);

using Column = google::protobuf::RepeatedField<double>;

Column* ColumnOf(pb::TraceSamples& s, int c) {
  Column* columns[] = {s.mutable_t(), s.mutable_x(), s.mutable_y(), s.mutable_z(),
                       s.mutable_fx(), s.mutable_fy(), s.mutable_fz()};
  return columns[c];
}

// Values that reach the edge cases of the estimator: zeros of both signs, the
// extremes of the double range, subnormals and non-finite values.
double SpecialValue(std::minstd_rand& rng) {
  static constexpr double kValues[] = {0.0,
                                       -0.0,
                                       1.0,
                                       -1.0,
                                       1e-300,
                                       std::numeric_limits<double>::denorm_min(),
                                       std::numeric_limits<double>::min(),
                                       1e150,
                                       -1e200,
                                       std::numeric_limits<double>::max(),
                                       std::numeric_limits<double>::infinity(),
                                       std::numeric_limits<double>::quiet_NaN()};
  return kValues[rng() % std::size(kValues)];
}

// One row-level edit of a decoded request with equal, non-empty columns.
void MutateRows(pb::TraceSamples& s, std::minstd_rand& rng) {
  const int n = s.t_size();
  const int row = static_cast<int>(rng() % n);
  switch (rng() % 6) {
    case 0: {  // duplicate a row in place (time no longer increases there)
      for (int c = 0; c < 7; ++c) ColumnOf(s, c)->Add(ColumnOf(s, c)->Get(n - 1));
      s.add_phases(s.phases(n - 1));
      for (int c = 0; c < 7; ++c) {
        Column& col = *ColumnOf(s, c);
        for (int i = n; i > row; --i) col.Set(i, col.Get(i - 1));
      }
      for (int i = n; i > row; --i) s.set_phases(i, s.phases(i - 1));
      break;
    }
    case 1: {  // delete a row
      for (int c = 0; c < 7; ++c) {
        Column& col = *ColumnOf(s, c);
        for (int i = row; i + 1 < n; ++i) col.Set(i, col.Get(i + 1));
        col.RemoveLast();
      }
      for (int i = row; i + 1 < n; ++i) s.set_phases(i, s.phases(i + 1));
      s.mutable_phases()->RemoveLast();
      break;
    }
    case 2:  // one value becomes special
      ColumnOf(s, static_cast<int>(rng() % 7))->Set(row, SpecialValue(rng));
      break;
    case 3: {  // one value scaled or nudged by a few ulps
      Column& col = *ColumnOf(s, static_cast<int>(rng() % 7));
      const double v = col.Get(row);
      const double factors[] = {10.0, 0.1, -1.0, 1e6, 1e-6};
      col.Set(row, rng() % 2 ? v * factors[rng() % std::size(factors)]
                             : std::nextafter(v, rng() % 2 ? INFINITY : -INFINITY));
      break;
    }
    case 4:  // a phase changes (out of order, or unspecified)
      s.set_phases(row, static_cast<pb::Phase>(rng() % 4));
      break;
    case 5: {  // a stretch of rows becomes a copy of its neighbours (a stuck sensor)
      const int length = 1 + static_cast<int>(rng() % 16);
      const int c = 1 + static_cast<int>(rng() % 6);
      Column& col = *ColumnOf(s, c);
      for (int i = row + 1; i < n && i <= row + length; ++i) col.Set(i, col.Get(row));
      break;
    }
  }
}

bool ColumnsUsable(const pb::TraceSamples& s) {
  const int n = s.t_size();
  return n > 0 && s.x_size() == n && s.y_size() == n && s.z_size() == n && s.fx_size() == n && s.fy_size() == n &&
         s.fz_size() == n && s.phases_size() == n;
}

}  // namespace

// Protobuf logs every string field with invalid UTF-8 (a parse failure, as in
// gRPC) to stderr: thousands of lines per second that slow the run and bury the
// reports in the log.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  google::protobuf::SetLogHandler(nullptr);
  return 0;
}

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                              unsigned int seed) {
  std::minstd_rand rng(seed);
  pb::SubmitTraceRequest request;
  if (rng() % 2 == 0 || !request.ParseFromArray(data, static_cast<int>(size)) ||
      !ColumnsUsable(request.samples())) {
    return LLVMFuzzerMutate(data, size, max_size);
  }
  MutateRows(*request.mutable_samples(), rng);
  const std::string bytes = request.SerializeAsString();
  if (bytes.size() > max_size) return LLVMFuzzerMutate(data, size, max_size);
  std::memcpy(data, bytes.data(), bytes.size());
  return bytes.size();
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace surfmap;
  if (size > kMaxInputBytes) return -1;  // -1: not added to the corpus
  pb::SubmitTraceRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;  // gRPC would refuse it too

  const absl::StatusOr<DragTrace> trace = DragTraceFromProto(request.samples(), kMaxSamples);
  if (!trace.ok()) {
    const absl::StatusCode code = trace.status().code();
    FUZZ_CHECK(code == absl::StatusCode::kInvalidArgument ||
                   (code == absl::StatusCode::kResourceExhausted && request.samples().t_size() > kMaxSamples),
               fuzz::Describe(trace.status()));
    return 0;
  }
  FUZZ_CHECK(static_cast<int>(trace->samples.size()) == request.samples().t_size(), "sample count changed");

  const absl::StatusOr<DragTrace> again = DragTraceFromProto(DragTraceToProto(*trace), kMaxSamples);
  FUZZ_CHECK(again.ok(), absl::StrCat("DragTraceToProto output does not convert back: ", fuzz::Describe(again.status())));
  FUZZ_CHECK(fuzz::SameTrace(*trace, *again), "DragTraceToProto -> DragTraceFromProto changed a value");

  if (!fuzz::FitAndCheck(*trace)) return 0;
  const absl::StatusOr<DragTrace> csv = ParseTraceCsv(FormatTraceCsv(*trace), "export.csv");
  FUZZ_CHECK(csv.ok(), absl::StrCat("a trace FitTrace accepted does not survive CSV export: ", fuzz::Describe(csv.status())));
  FUZZ_CHECK(fuzz::SameTrace(*trace, *csv), "CSV export changed a value of a fitted trace");
  return 0;
}
