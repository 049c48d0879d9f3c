#include "server/estimate/trace_csv.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <optional>
#include <system_error>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace surfmap {
namespace {

// Column order of the internal record; the header may name them in any order.
enum Column { kT, kX, kY, kZ, kFx, kFy, kFz, kPhase, kColumnCount };
constexpr std::array<std::string_view, kColumnCount> kColumnNames = {
    "t", "x", "y", "z", "fx", "fy", "fz", "phase"};
constexpr std::string_view kExpectedHeader = "t,x,y,z,fx,fy,fz,phase";

// This abseil build's absl::string_view is not std::string_view.
absl::string_view A(std::string_view s) { return absl::string_view(s.data(), s.size()); }

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// Splits `line` at commas into `fields`; returns the number of fields, or
// fields.size() + 1 when there are more than fit.
template <std::size_t N>
std::size_t SplitFields(std::string_view line, std::array<std::string_view, N>& fields) {
  std::size_t count = 0;
  while (true) {
    const std::size_t comma = line.find(',');
    const std::string_view field = line.substr(0, comma);
    if (count < N) fields[count] = Trim(field);
    ++count;
    if (comma == std::string_view::npos) break;
    line.remove_prefix(comma + 1);
  }
  return count;
}

std::optional<DragPhase> PhaseFromName(std::string_view name) {
  if (name == "fwd") return DragPhase::kForward;
  if (name == "pause") return DragPhase::kPause;
  if (name == "rev") return DragPhase::kReverse;
  return std::nullopt;
}

class LineError {
 public:
  LineError(std::string_view source) : source_(source) {}
  absl::Status operator()(int line, std::string_view problem) const {
    return absl::InvalidArgumentError(absl::StrCat(A(source_), ":", line, ": ", A(problem)));
  }

 private:
  std::string_view source_;
};

}  // namespace

absl::StatusOr<DragTrace> ParseTraceCsv(std::string_view text, std::string_view source) {
  const LineError error(source);
  DragTrace trace;
  // A trace line is ~70 characters; reserving avoids regrowth for typical input.
  trace.samples.reserve(text.size() / 48 + 1);

  std::array<int, kColumnCount> field_of_column{};  // column -> field index
  bool have_header = false;
  int line_number = 0;
  double previous_t = 0.0;
  DragPhase previous_phase = DragPhase::kForward;
  bool have_forward = false, have_reverse = false;
  std::array<std::string_view, kColumnCount> fields;

  while (!text.empty()) {
    ++line_number;
    const std::size_t newline = text.find('\n');
    const std::string_view line = Trim(text.substr(0, newline));
    text.remove_prefix(newline == std::string_view::npos ? text.size() : newline + 1);
    if (line.empty() || line.front() == '#') continue;

    const std::size_t count = SplitFields(line, fields);
    if (!have_header) {
      // The first meaningful line must be the header; data here means it is missing.
      double probe;
      const std::string_view first = fields[0];
      if (!first.empty() &&
          std::from_chars(first.data(), first.data() + first.size(), probe).ec == std::errc()) {
        return error(line_number, absl::StrCat("missing header line (found data; expected ",
                                               A(kExpectedHeader), ")"));
      }
      if (count > kColumnCount) {
        return error(line_number, absl::StrCat("header has ", count, " columns, expected the ",
                                               kColumnCount, " columns ", A(kExpectedHeader)));
      }
      field_of_column.fill(-1);
      for (std::size_t f = 0; f < count; ++f) {
        int column = -1;
        for (int c = 0; c < kColumnCount; ++c) {
          if (fields[f] == kColumnNames[c]) column = c;
        }
        if (column < 0) {
          return error(line_number, absl::StrCat("header: unknown column '", A(fields[f]),
                                                 "' (expected ", A(kExpectedHeader), ")"));
        }
        if (field_of_column[column] >= 0) {
          return error(line_number, absl::StrCat("header: duplicate column '", A(fields[f]), "'"));
        }
        field_of_column[column] = static_cast<int>(f);
      }
      for (int c = 0; c < kColumnCount; ++c) {
        if (field_of_column[c] < 0) {
          return error(line_number, absl::StrCat("header: missing column '", A(kColumnNames[c]),
                                                 "' (expected ", A(kExpectedHeader), ")"));
        }
      }
      have_header = true;
      continue;
    }

    if (count != kColumnCount) {
      return error(line_number, absl::StrCat("expected ", kColumnCount, " fields, found ", count));
    }
    std::array<double, kPhase> values;
    for (int c = 0; c < kPhase; ++c) {
      const std::string_view field = fields[field_of_column[c]];
      if (field.empty()) {
        return error(line_number, absl::StrCat("column '", A(kColumnNames[c]), "' is empty"));
      }
      const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), values[c]);
      if (ec == std::errc::result_out_of_range) {
        return error(line_number, absl::StrCat("column '", A(kColumnNames[c]), "': '", A(field),
                                               "' is out of the range of a double"));
      }
      if (ec != std::errc() || end != field.data() + field.size()) {
        return error(line_number, absl::StrCat("column '", A(kColumnNames[c]), "': '", A(field),
                                               "' is not a number"));
      }
      if (!std::isfinite(values[c])) {
        return error(line_number, absl::StrCat("column '", A(kColumnNames[c]), "': '", A(field),
                                               "' is not finite"));
      }
    }
    const std::string_view phase_name = fields[field_of_column[kPhase]];
    const std::optional<DragPhase> phase = PhaseFromName(phase_name);
    if (!phase) {
      return error(line_number, absl::StrCat("unknown phase '", A(phase_name),
                                             "' (expected fwd, pause or rev)"));
    }
    if (!trace.samples.empty()) {
      if (!(values[kT] > previous_t)) {
        return error(line_number, absl::StrCat("time ", values[kT],
                                               " s does not increase (previous sample at ",
                                               previous_t, " s)"));
      }
      if (static_cast<int>(*phase) < static_cast<int>(previous_phase)) {
        return error(line_number,
                     absl::StrCat("phase '", A(phase_name), "' after '", A(DragPhaseName(previous_phase)),
                                  "': phases must come in the order fwd, pause, rev"));
      }
    } else if (*phase != DragPhase::kForward) {
      return error(line_number, absl::StrCat("first sample has phase '", A(phase_name),
                                             "': a trace starts with its forward (fwd) pass"));
    }
    previous_t = values[kT];
    previous_phase = *phase;
    have_forward |= *phase == DragPhase::kForward;
    have_reverse |= *phase == DragPhase::kReverse;

    DragSample& sample = trace.samples.emplace_back();
    sample.t = values[kT];
    sample.position = Eigen::Vector3d(values[kX], values[kY], values[kZ]);
    sample.force = Eigen::Vector3d(values[kFx], values[kFy], values[kFz]);
    sample.phase = *phase;
  }

  const int last_line = line_number == 0 ? 1 : line_number;
  if (!have_header) {
    return error(last_line, absl::StrCat("missing header line (expected ", A(kExpectedHeader), ")"));
  }
  if (!have_forward) return error(last_line, "end of input: no forward (fwd) samples");
  if (!have_reverse) return error(last_line, "end of input: no reverse (rev) samples");
  return trace;
}

namespace {

void AppendDouble(std::string& out, double value) {
  char buffer[32];
  // Shortest representation that parses back to the same double.
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

}  // namespace

std::string FormatTraceCsv(const DragTrace& trace) {
  std::string out;
  out.reserve(32 + trace.samples.size() * 128);
  out.append(kExpectedHeader);
  out.push_back('\n');
  for (const DragSample& s : trace.samples) {
    AppendDouble(out, s.t);
    for (int i = 0; i < 3; ++i) {
      out.push_back(',');
      AppendDouble(out, s.position[i]);
    }
    for (int i = 0; i < 3; ++i) {
      out.push_back(',');
      AppendDouble(out, s.force[i]);
    }
    out.push_back(',');
    out.append(DragPhaseName(s.phase));
    out.push_back('\n');
  }
  return out;
}

}  // namespace surfmap
