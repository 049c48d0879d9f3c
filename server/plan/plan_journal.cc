#include "server/plan/plan_journal.h"

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "server/plan/line_sample_json.h"

namespace surfmap {
namespace {

using nlohmann::json;

absl::Status Malformed(const std::string& what) {
  return absl::InvalidArgumentError(absl::StrCat("plan journal entry: ", what));
}

}  // namespace

std::string PlanJournalEntryToJson(const PlanJournalEntry &entry) {
  json j = {{"sequence", entry.sequence}};
  if (entry.kind == PlanJournalEntry::Kind::kImport) {
    j["op"] = "import";
    j["line"] = entry.line ? LineSampleToJson(*entry.line) : json::object();
    j["position"] = {entry.position.x(), entry.position.y(), entry.position.z()};
  } else if (entry.kind == PlanJournalEntry::Kind::kFit) {
    j["op"] = "fit";
    const TextureParams fit = entry.line ? SummaryTexture(*entry.line) : entry.fit;
    j["fit"] = {{"mu", fit.mu}, {"mu_std", fit.mu_std}, {"reflection", fit.reflection}, {"sigma", fit.sigma}};
    if (entry.line) j["line"] = LineSampleToJson(*entry.line);
  } else {
    j["op"] = "failure";
    j["reason"] = entry.reason;
    if (entry.failure != FailureKind::kTransient) j["kind"] = std::string(FailureKindName(entry.failure));
  }
  if (entry.issued_after) j["issued"] = *entry.issued_after;
  return j.dump();
}

absl::StatusOr<PlanJournalEntry> PlanJournalEntryFromJson(std::string_view text) {
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) return Malformed("not a JSON object");
  PlanJournalEntry entry;
  auto op = j.find("op");
  if (op == j.end() || !op->is_string()) return Malformed("\"op\" is missing or not a string");
  auto sequence = j.find("sequence");
  if (sequence == j.end() || !sequence->is_number_unsigned()) {
    return Malformed("\"sequence\" is missing or not an unsigned integer");
  }
  entry.sequence = sequence->get<std::uint64_t>();
  if (auto issued = j.find("issued"); issued != j.end()) {
    if (!issued->is_number_unsigned() || issued->get<std::uint64_t>() > 1'000'000'000) {
      return Malformed("\"issued\" is not a count of commands");
    }
    entry.issued_after = static_cast<int>(issued->get<std::uint64_t>());
  }
  if (*op == "fit") {
    auto fit = j.find("fit");
    if (fit == j.end() || !fit->is_object()) return Malformed("\"fit\" is missing or not an object");
    for (const char *key : {"mu", "mu_std", "sigma"}) {
      auto v = fit->find(key);
      if (v == fit->end() || !v->is_number())
        return Malformed(absl::StrCat("fit.", key, " is missing or not a number"));
    }
    auto reflection = fit->find("reflection");
    if (reflection == fit->end() || !reflection->is_array()) return Malformed("fit.reflection is not an array");
    for (const json &k : *reflection) {
      if (!k.is_number()) return Malformed("fit.reflection holds a non-number");
      entry.fit.reflection.push_back(k.get<double>());
    }
    entry.fit.mu = (*fit)["mu"].get<double>();
    entry.fit.mu_std = (*fit)["mu_std"].get<double>();
    entry.fit.sigma = (*fit)["sigma"].get<double>();
    entry.kind = PlanJournalEntry::Kind::kFit;
    if (auto line = j.find("line"); line != j.end()) {
      absl::StatusOr<LineSample> parsed = LineSampleFromJson(*line, "plan journal entry: line");
      if (!parsed.ok()) return parsed.status();
      entry.line = *std::move(parsed);
    }
  } else if (*op == "import") {
    entry.kind = PlanJournalEntry::Kind::kImport;
    auto line = j.find("line");
    if (line == j.end()) return Malformed("\"line\" is missing");
    absl::StatusOr<LineSample> parsed = LineSampleFromJson(*line, "plan journal entry: line");
    if (!parsed.ok()) return parsed.status();
    entry.line = *std::move(parsed);
    auto p = j.find("position");
    if (p == j.end() || !p->is_array() || p->size() != 3 || !(*p)[0].is_number() || !(*p)[1].is_number() ||
        !(*p)[2].is_number()) {
      return Malformed("\"position\" is missing or not 3 numbers");
    }
    entry.position = Eigen::Vector3d((*p)[0].get<double>(), (*p)[1].get<double>(), (*p)[2].get<double>());
  } else if (*op == "failure") {
    auto reason = j.find("reason");
    if (reason == j.end() || !reason->is_string()) return Malformed("\"reason\" is missing or not a string");
    entry.reason = reason->get<std::string>();
    entry.kind = PlanJournalEntry::Kind::kFailure;
    if (auto kind = j.find("kind"); kind != j.end()) {
      std::optional<FailureKind> parsed = kind->is_string() ? ParseFailureKind(kind->get<std::string>()) : std::nullopt;
      if (!parsed) return Malformed("\"kind\" is not \"transient\" or \"unreachable\"");
      entry.failure = *parsed;
    }
  } else {
    return Malformed(absl::StrCat("\"op\" is \"", op->get<std::string>(), "\", not \"fit\", \"failure\" or \"import\""));
  }
  return entry;
}

absl::Status ApplyPlanJournalEntry(const PlanJournalEntry &entry, SamplingPlan &plan) {
  if (entry.kind == PlanJournalEntry::Kind::kFailure) {
    return plan.RecordFailure(entry.sequence, entry.reason, entry.failure);
  }
  if (entry.kind == PlanJournalEntry::Kind::kImport) {
    if (!entry.line) return absl::InvalidArgumentError("plan journal entry: an import without its line");
    return plan.RecordImportedLineSample(*entry.line, entry.position);
  }
  return entry.line ? plan.RecordLineSample(entry.sequence, *entry.line) : plan.RecordFit(entry.sequence, entry.fit);
}

}  // namespace surfmap
