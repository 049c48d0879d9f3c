#include "clients/cli/registration_commands.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <google/protobuf/util/json_util.h>
#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "proto/surfmap/v1/surfmap.grpc.pb.h"

namespace surfmap::cli {
namespace {

namespace pb = ::surfmap::v1;

struct RegisterArgs {
  int64_t object_id = 0;
  std::string rig;
  std::string pose;     // W,X,Y,Z,TX,TY,TZ
  double tip_radius_mm = 0;
  std::string sensor;   // W,X,Y,Z
  std::string json_file;
};

// "a,b,c" -> numbers, exactly `n` of them.
bool ParseNumbers(const std::string& text, size_t n, std::vector<double>* out) {
  out->clear();
  for (absl::string_view part : absl::StrSplit(text, ',')) {
    double v = 0;
    if (!absl::SimpleAtod(part, &v)) return false;
    out->push_back(v);
  }
  return out->size() == n;
}

void RunRegister(RemoteCli& cli, const RegisterArgs& args) {
  pb::SetRigRegistrationRequest request;
  pb::RigRegistration* r = request.mutable_registration();
  if (!args.json_file.empty()) {
    std::ifstream in(args.json_file);
    if (!in) return FailUsage(cli, args.json_file + ": cannot open file");
    std::stringstream text;
    text << in.rdbuf();
    const auto parsed = google::protobuf::util::JsonStringToMessage(text.str(), r);
    if (!parsed.ok()) {
      return FailUsage(cli, args.json_file + ": not a RigRegistration in JSON: " + std::string(parsed.message()));
    }
  } else {
    std::vector<double> pose, sensor;
    if (!ParseNumbers(args.pose, 7, &pose)) {
      return FailUsage(cli, "--pose must be W,X,Y,Z,TX,TY,TZ (a unit quaternion, then a translation in mm), got '" +
                                args.pose + "'");
    }
    pb::Quaternion* q = r->mutable_object_pose()->mutable_rotation();
    q->set_w(pose[0]), q->set_x(pose[1]), q->set_y(pose[2]), q->set_z(pose[3]);
    pb::Vec3* t = r->mutable_object_pose()->mutable_translation_mm();
    t->set_x(pose[4]), t->set_y(pose[5]), t->set_z(pose[6]);
    r->set_tip_radius_mm(args.tip_radius_mm);
    if (!args.sensor.empty()) {
      if (!ParseNumbers(args.sensor, 4, &sensor)) {
        return FailUsage(cli, "--sensor must be W,X,Y,Z (a unit quaternion), got '" + args.sensor + "'");
      }
      pb::Quaternion* s = r->mutable_sensor_rotation();
      s->set_w(sensor[0]), s->set_x(sensor[1]), s->set_y(sensor[2]), s->set_z(sensor[3]);
    }
  }
  // The command line names the object and the rig (they win over the file).
  r->set_object_id(args.object_id);
  if (!args.rig.empty()) r->set_rig_name(args.rig);
  auto stub = pb::ObjectService::NewStub(cli.Channel());
  pb::SetRigRegistrationResponse response;
  if (!CallRpc(cli, "SetRigRegistration", *stub, &pb::ObjectService::Stub::SetRigRegistration, request, &response)) {
    return;
  }
  std::printf("%s\n", MessageToJson(response.registration()).c_str());
}

}  // namespace

void AddRegistrationCommands(CLI::App& object, std::shared_ptr<RemoteCli> cli) {
  auto args = std::make_shared<RegisterArgs>();
  CLI::App* reg = object.add_subcommand(
      "register", "Register a rig to an object: the object's pose in the rig's base frame (mm), the tool-tip radius, "
                  "the F/T sensor's orientation; stores the next version and prints it (JSON)");
  reg->add_option("object", args->object_id, "Object id")->required();
  reg->add_option("--rig", args->rig, "Rig name: the rig_id it leases with")->required();
  auto* pose = reg->add_option("--pose", args->pose, "W,X,Y,Z,TX,TY,TZ: p_base = R(w,x,y,z) p_object + t (mm)");
  auto* tip = reg->add_option("--tip-radius-mm", args->tip_radius_mm, "Tool-tip radius, mm (0..50; with --pose)");
  auto* sensor = reg->add_option("--sensor", args->sensor,
                                 "W,X,Y,Z: f_base = S f_sensor (with --pose; default: aligned with the base)");
  auto* json = reg->add_option("--json", args->json_file, "A RigRegistration in JSON (instead of --pose ...)")
                   ->check(CLI::ExistingFile);
  // A pose without a tip radius would register a 0 mm tip, and --json would
  // silently drop --tip-radius-mm/--sensor: both are usage errors.
  pose->excludes(json);
  pose->needs(tip);
  tip->excludes(json);
  sensor->excludes(json);
  reg->callback([cli, args, pose, json] {
    if (pose->count() == 0 && json->count() == 0) return FailUsage(*cli, "give --pose (with --tip-radius-mm) or --json");
    RunRegister(*cli, *args);
  });

  struct ShowArgs {
    int64_t object_id = 0;
    std::string rig;
    bool history = false;
  };
  auto show = std::make_shared<ShowArgs>();
  CLI::App* list = object.add_subcommand("registrations", "A object's rig registrations (JSON): the latest per rig, "
                                                          "or with --history every version");
  list->add_option("object", show->object_id, "Object id")->required();
  list->add_option("--rig", show->rig, "Only this rig");
  list->add_flag("--history", show->history, "Every version, oldest first");
  list->callback([cli, show] {
    auto stub = pb::ObjectService::NewStub(cli->Channel());
    pb::ListRigRegistrationsRequest request;
    request.set_object_id(show->object_id);
    request.set_include_history(show->history);
    pb::ListRigRegistrationsResponse response;
    if (!CallRpc(*cli, "ListRigRegistrations", *stub, &pb::ObjectService::Stub::ListRigRegistrations, request,
                 &response)) {
      return;
    }
    pb::ListRigRegistrationsResponse shown;
    for (const pb::RigRegistration& r : response.registrations()) {
      if (show->rig.empty() || r.rig_name() == show->rig) *shown.add_registrations() = r;
    }
    std::printf("%s\n", MessageToJson(shown).c_str());
  });
}

}  // namespace surfmap::cli
