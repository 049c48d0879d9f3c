// The records the store keeps, as plain structs: ids, numbers, JSON text and
// BLOBs. Storage knows nothing of proto, gRPC, meshes or estimators; the service
// decides what goes into the JSON fields (the store only checks it is valid
// JSON, via SQLite's json_valid()).
//
// Ids are positive int64 assigned by the store; 0 means "none / not set".
// Times are milliseconds since the Unix epoch (UTC).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "storage/stored_sample.h"

namespace surfmap {

// ---- States (stored as their lower-case names) ----------------------------

enum class JobState { kRunning, kPaused, kCompleted, kCancelled };
// Running <-> paused; running/paused -> completed/cancelled; completed and
// cancelled are final.
std::string_view JobStateName(JobState state);        // "running", ...
absl::StatusOr<JobState> ParseJobState(std::string_view name);
bool IsJobTransitionAllowed(JobState from, JobState to);

enum class CommandState { kPending, kLeased, kDone, kFailed };
std::string_view CommandStateName(CommandState state);  // "pending", ...
absl::StatusOr<CommandState> ParseCommandState(std::string_view name);

// ---- Stored records ---------------------------------------------------------

struct ObjectRecord {
  int64_t id = 0;
  std::string name;
  std::string mesh_format;   // "obj" or "ply"
  std::string mesh_bytes;    // the upload exactly as sent (BLOB)
  int64_t control_vertices = 0;  // of the control mesh, as parsed by the service
  int64_t control_faces = 0;
  int64_t created_unix_ms = 0;
  std::string metadata_json = "{}";  // provenance (the service's JSON object)
  // What the mesh is: "control_mesh" (a Loop control mesh, or a dense scan
  // that is the surface itself) or "facets" (flat triangles that are the
  // surface, sharp edges and all: a CAD export). server/mesh/flat_refine.h.
  std::string surface = "control_mesh";
};

struct JobRecord {
  int64_t id = 0;
  int64_t object_id = 0;
  JobState state = JobState::kRunning;
  std::string params_json;   // the job's parameters, as the service chose them
  int64_t created_unix_ms = 0;
  int64_t updated_unix_ms = 0;  // last state change
  std::string metadata_json = "{}";  // provenance (the service's JSON object)
};

// The sampling plan's serialized state: a checkpoint (plan_json) plus the
// journal entries written after it, oldest first, each in the same
// transaction as the trace (or failure) that changed the plan. The store does
// not interpret either; the service replays the journal onto the checkpoint.
// revision starts at 1 and increases by one with every change (a new
// checkpoint or a journal entry): revision = checkpoint revision + journal size.
struct PlanRecord {
  int64_t job_id = 0;
  std::string plan_json;
  std::vector<std::string> journal;
  int64_t revision = 0;
  int64_t updated_unix_ms = 0;  // of the checkpoint
};

// One probe command: measure the site (level, vertex) of the job's object.
// Once done (answered by a trace), a command is never leased again, so its
// lease_owner names the rig that measured it.
struct CommandRecord {
  int64_t id = 0;
  int64_t job_id = 0;
  int32_t site_level = 0;
  int64_t site_vertex = 0;
  std::string command_json;   // what the rig must do (pose, force, path...)
  CommandState state = CommandState::kPending;
  std::string lease_owner;    // rig holding / last holding the lease; "" if never leased
  int64_t lease_deadline_unix_ms = 0;  // lease valid while now < deadline
  int32_t attempt = 0;        // number of times it has been leased
  int64_t created_unix_ms = 0;
};

// A drag trace, every sample kept losslessly (see stored_sample.h).
struct TraceRecord {
  int64_t id = 0;
  int64_t command_id = 0;     // at most one trace per command
  int64_t job_id = 0;
  int64_t n_samples = 0;
  std::vector<StoredSample> samples;  // empty when listed without samples
  int64_t received_unix_ms = 0;
  // Provenance, and for an imported trace where it came from (the service's
  // JSON object).
  std::string metadata_json = "{}";
  std::string import_sha256;  // imported traces only: the file's SHA-256 (hex)
};

// An estimator's output for a trace. version 1 is the fit made on arrival;
// 2, 3, ... are refits (AddFits gives a whole batch one version number).
struct FitRecord {
  int64_t id = 0;
  int64_t trace_id = 0;
  int32_t version = 0;
  std::string estimator_name;
  std::string estimator_version;
  std::string options_json;   // estimator options used (provenance)
  std::string result_json;    // the full result as the service serialized it
  // Copies of the headline numbers, as columns for queries; empty when the
  // estimator did not produce them (NaN is stored as empty, too).
  std::optional<double> mu, a1, a2, sigma;
  int64_t created_unix_ms = 0;
};

struct EventRecord {
  int64_t id = 0;             // increases with every event written
  int64_t job_id = 0;         // 0: not about one job
  int64_t unix_ms = 0;
  std::string kind;           // e.g. "job_created", "trace_accepted"
  std::string detail_json;
};

// ---- Inputs to writes -------------------------------------------------------

struct NewObject {
  std::string name;
  std::string mesh_format;    // "obj" or "ply"
  std::string mesh_bytes;
  int64_t control_vertices = 0;
  int64_t control_faces = 0;
  std::string metadata_json = "{}";
  std::string surface = "control_mesh";  // as ObjectRecord::surface
};

// The newest traces of a job and the time of its last change, for restoring a
// job's runtime without reading every row.
struct JobActivity {
  std::optional<TraceRecord> latest_trace;       // highest id, without samples
  std::optional<int64_t> last_event_unix_ms;     // newest event time (every change writes one)
};

// Commands leased to a rig with a lease still valid, in all and per site level
// (levels without any are absent).
struct LeasedCounts {
  int total = 0;
  std::map<int, int> by_level;
};

struct NewCommand {
  int32_t site_level = 0;
  int64_t site_vertex = 0;
  std::string command_json;
};

struct NewEvent {
  std::string kind;
  std::string detail_json = "{}";
};

// A fit to store; the store assigns id, trace_id, version and time.
struct NewFit {
  std::string estimator_name;
  std::string estimator_version;
  std::string options_json = "{}";
  std::string result_json = "{}";
  std::optional<double> mu, a1, a2, sigma;
};

struct NewJob {
  int64_t object_id = 0;
  std::string params_json = "{}";
  std::string metadata_json = "{}";
  std::string plan_json;             // initial plan state (revision 1)
  std::vector<NewCommand> commands;  // initial commands, all pending
  std::vector<NewEvent> events;      // e.g. {"job_created", ...}; job_id filled in
};

struct CreatedJob {
  JobRecord job;
  std::vector<int64_t> command_ids;  // in the order of NewJob::commands
};

struct LeaseRequest {
  int64_t job_id = 0;               // 0: any running job
  std::string owner;                // the rig; must not be empty
  int64_t now_unix_ms = 0;
  int64_t lease_duration_ms = 0;    // > 0
};

// A trace recorded elsewhere (a hand drag, another program's file), not the
// answer to a leased command. The write stores `command` (the command the
// path implies) as done, measured by `source`, then the trace as an answer to
// it. Idempotent per job on sha256: a second import of the same file writes
// nothing and answers already_accepted with the stored trace (whatever the
// job's state now). The job must be running or paused.
struct TraceImport {
  NewCommand command;
  std::string source;   // who or what recorded it (the command's lease_owner)
  std::string sha256;   // of the imported file, 64 lower-case hex digits
};

// The key write: a rig's trace for a leased command, with everything it changed.
struct AcceptTraceRequest {
  int64_t command_id = 0;
  int64_t job_id = 0;               // must be the command's job
  std::string lease_owner;          // if not empty, must hold the command's lease
  // The trace: at least one sample, given either as samples or already
  // encoded (EncodeSamples), so a caller can pay for the encoding outside its
  // own locks. Exactly one of the two is non-empty.
  std::vector<StoredSample> samples;
  std::string encoded_samples;
  std::optional<NewFit> fit;        // stored as version 1
  // The plan change, one of: a new checkpoint (the whole plan state after
  // this trace; the journal is cleared), or a journal entry appended to the
  // stored plan. Both empty: plan unchanged.
  std::string new_plan_json;
  std::string plan_journal_entry;  // used only when new_plan_json is empty
  // If > 0 and the plan changes, the stored plan must still be at this
  // revision (the plan the service updated); otherwise ABORTED, so that two
  // traces of one job accepted concurrently cannot lose a plan update.
  int64_t expected_plan_revision = 0;
  std::vector<NewCommand> new_commands;   // sites the plan added (pending)
  std::optional<JobState> new_job_state;  // e.g. completed when the plan is done
  std::vector<NewEvent> events;           // job_id filled in
  // Also lease the rig's next command in the same transaction (one durable
  // write per trace cycle instead of two). Not done when the write fails.
  std::optional<LeaseRequest> lease_next;
  // Stored with the trace (provenance; see TraceRecord).
  std::string metadata_json = "{}";
  // An imported trace (see TraceImport); command_id and lease_owner are then
  // unused (0 and empty).
  std::optional<TraceImport> import;
  // The frame the samples were sent in; "" or "object": the object's frame
  // (nothing more is stored). Otherwise registration_id names the
  // registration the service converted them with.
  std::string frame;
  int64_t registration_id = 0;
};

// ---- Rig registrations (frames and calibration; docs/trace-format.md) ----
// What a rig registered for an object: the object's pose in the rig's base
// frame, the tool-tip radius, the F/T sensor's orientation, as JSON the
// service writes (server/frames/rig_registration.h). Never changed once
// stored: registering again for the same (object, rig) adds the next version,
// so every stored trace's registration stays readable.
struct NewRigRegistration {
  int64_t object_id = 0;
  std::string rig_name;           // the rig_id the rig leases with
  std::string registration_json;
};
struct RigRegistrationRecord {
  int64_t id = 0;
  int64_t object_id = 0;
  std::string rig_name;
  int32_t version = 0;            // 1, 2, ... per (object, rig)
  int64_t created_unix_ms = 0;
  std::string registration_json;
};
// The frame a stored trace was sent in ("object", "rig_base",
// "rig_base_sensor_forces") and the registration it was converted with (0 for
// "object"). The samples are stored as sent.
struct TraceFrameRecord {
  std::string frame = "object";
  int64_t registration_id = 0;
};

struct AcceptTraceResult {
  int64_t trace_id = 0;
  int64_t fit_id = 0;               // 0 if no fit was stored
  int64_t plan_revision = 0;        // the plan's revision after the write
  std::vector<int64_t> new_command_ids;  // empty when already_accepted
  // True if this rig's identical trace for this command was already stored
  // (a retry after a lost reply): nothing was written, everything below is
  // what the first write stored.
  bool already_accepted = false;
  // lease_next: the command leased, if one was ready. For a retry: the
  // command the first write leased to this rig, while its lease holds.
  std::optional<CommandRecord> next_command;
  std::optional<FitRecord> fit;     // the fit version 1 as stored (also for a retry)
  int64_t accepted_unix_ms = 0;     // the trace's and fit's stored time (also for a retry)
  int64_t command_id = 0;           // the command answered (an import's implied command)
  std::string metadata_json = "{}"; // the trace's provenance as stored (also for a retry: the first one's)
};

// A trace refused as implausible for its command: kept, out of the map.
struct RejectedTraceRecord {
  int64_t id = 0;
  int64_t command_id = 0;
  int64_t job_id = 0;
  std::string rig_id;
  std::string check_name;     // which check refused it ("offset", "friction", ...)
  std::string message;        // the refusal as the rig heard it
  int64_t n_samples = 0;
  std::vector<StoredSample> samples;  // empty when listed without samples
  int64_t received_unix_ms = 0;
  std::string import_sha256;  // a refused import's file ("" otherwise)
  std::string frame = "object";  // as sent (see TraceFrameRecord)
  int64_t registration_id = 0;
};

struct NewRejectedTrace {
  int64_t command_id = 0;
  int64_t job_id = 0;
  std::string rig_id;
  std::string check_name;
  std::string message;
  std::string encoded_samples;  // EncodeSamples
  std::vector<NewEvent> events;
  // A refused import: command_id is 0 and this command (the one its path
  // implies) is stored first, as failed, with rig_id as its lease owner.
  std::optional<NewCommand> implied_command;
  // A refused import's file (64 lower-case hex digits; required with
  // implied_command): kept once per job; the same file again writes nothing
  // and answers the stored rejected trace's id.
  std::string import_sha256;
  // The frame the samples were sent in ("" or "object", or a rig's frame with
  // the registration they were converted with), as for AcceptTraceRequest.
  std::string frame;
  int64_t registration_id = 0;
};

// A trace with the command it answers and one of its fits, read in one
// snapshot (one read transaction): the three always belong together.
struct SampleRecord {
  TraceRecord trace;   // without samples unless asked for
  CommandRecord command;  // done: lease_owner is the rig that measured the trace
  FitRecord fit;
};

// A rig could not measure a leased command: the command is marked failed and
// the plan's reaction (a retry command, or the site failed for good) is
// written with it, atomically.
struct FailCommandRequest {
  int64_t command_id = 0;
  int64_t job_id = 0;               // must be the command's job
  std::string lease_owner;          // if not empty, must hold the command's lease
  std::string reason;               // stored in the command's failure event
  std::string new_plan_json;        // as for AcceptTraceRequest
  std::string plan_journal_entry;   // as for AcceptTraceRequest
  int64_t expected_plan_revision = 0;  // as for AcceptTraceRequest
  std::vector<NewCommand> new_commands;
  std::optional<JobState> new_job_state;
  std::vector<NewEvent> events;
};

struct FailCommandResult {
  int64_t plan_revision = 0;
  std::vector<int64_t> new_command_ids;
};

struct JobStateChange {
  int64_t job_id = 0;
  JobState new_state = JobState::kRunning;
  std::vector<NewEvent> events;
};

// A refit: new fits for existing traces.
struct TraceRefit {
  int64_t trace_id = 0;
  NewFit fit;
};

}  // namespace surfmap
