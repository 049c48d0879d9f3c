#include "clients/cli/object_commands.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <google/protobuf/util/time_util.h>
#include "absl/strings/ascii.h"
#include "clients/cli/provenance_options.h"
#include "clients/cli/registration_commands.h"
#include "proto/surfmap/v1/surfmap.grpc.pb.h"

namespace surfmap::cli {
namespace {

namespace pb = ::surfmap::v1;

std::string_view FormatName(pb::MeshFormat format) {
  switch (format) {
    case pb::MESH_FORMAT_OBJ: return "obj";
    case pb::MESH_FORMAT_PLY: return "ply";
    case pb::MESH_FORMAT_STL: return "stl";
    default: return "?";
  }
}

void PrintObjectTable(const google::protobuf::RepeatedPtrField<pb::ObjectInfo>& objects) {
  std::printf("%6s  %-30s %-6s %9s %9s  %-24s %s\n", "id", "name", "format", "vertices", "faces", "created",
              "operator / specimen");
  for (const pb::ObjectInfo& o : objects) {
    std::printf("%6lld  %-30s %-6s %9d %9d  %-24s %s\n", static_cast<long long>(o.object_id()), o.name().c_str(),
                std::string(FormatName(o.format())).c_str(), o.control_vertex_count(), o.control_face_count(),
                google::protobuf::util::TimeUtil::ToString(o.created()).c_str(),
                (o.provenance().operator_name() + " / " + o.provenance().specimen()).c_str());
  }
}

struct UploadArgs {
  std::string file;
  std::string name;
  std::string units;     // mm, cm, m, in; empty = not stated (the server assumes mm)
  double scale = 0;      // mm per file unit; 0 = not given
  bool facets = false;   // the flat facets are the surface (a CAD export)
  ProvenanceArgs provenance;
  bool json = false;
};

void RunUpload(RemoteCli& cli, const UploadArgs& args) {
  const std::filesystem::path path(args.file);
  const std::string ext = absl::AsciiStrToLower(path.extension().string());
  pb::UploadObjectRequest request;
  if (ext == ".obj") {
    request.set_format(pb::MESH_FORMAT_OBJ);
  } else if (ext == ".ply") {
    request.set_format(pb::MESH_FORMAT_PLY);
  } else if (ext == ".stl") {
    request.set_format(pb::MESH_FORMAT_STL);
  } else {
    return FailUsage(cli, args.file + ": unknown mesh format '" + ext + "' (expected .obj, .ply or .stl)");
  }
  if (args.scale != 0) {
    request.set_scale(args.scale);
  } else if (args.units == "mm") {
    request.set_units(pb::LENGTH_UNIT_MM);
  } else if (args.units == "cm") {
    request.set_units(pb::LENGTH_UNIT_CM);
  } else if (args.units == "m") {
    request.set_units(pb::LENGTH_UNIT_M);
  } else if (args.units == "in") {
    request.set_units(pb::LENGTH_UNIT_IN);
  } else if (!args.units.empty()) {
    return FailUsage(cli, "--units must be mm, cm, m or in, got '" + args.units + "'");
  }
  if (args.facets) {
    request.set_surface(pb::OBJECT_SURFACE_FACETS);
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return FailUsage(cli, args.file + ": cannot open file");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  request.set_mesh(bytes.str());
  request.set_name(args.name.empty() ? path.stem().string() : args.name);
  std::string error;
  if (!ProvenanceFromArgs(args.provenance, request.mutable_provenance(), &error)) return FailUsage(cli, error);
  pb::UploadObjectResponse response;
  auto stub = pb::ObjectService::NewStub(cli.Channel());
  if (!CallRpc(cli, "UploadObject", *stub, &pb::ObjectService::Stub::UploadObject, request, &response)) return;
  // The id (or the ObjectInfo) on stdout for scripts; what was done to the
  // mesh on stderr, for the person uploading it.
  if (args.json) {
    std::printf("%s\n", MessageToJson(response.object()).c_str());
  } else {
    std::printf("%lld\n", static_cast<long long>(response.object().object_id()));
  }
  const pb::Vec3& e = response.extent_mm();
  std::fprintf(stderr, "object %lld: %d vertices, %d faces, %.4g x %.4g x %.4g mm, area %.4g mm^2 (x %g mm per unit)\n",
               static_cast<long long>(response.object().object_id()), response.object().control_vertex_count(),
               response.object().control_face_count(), e.x(), e.y(), e.z(), response.area_mm2(), response.scale_mm());
  for (const pb::MeshRepair& r : response.repairs()) {
    std::fprintf(stderr, "repaired: %s x %d (%s)\n", r.kind().c_str(), r.count(), r.detail().c_str());
  }
  for (const std::string& w : response.warnings()) std::fprintf(stderr, "warning: %s\n", w.c_str());
}

}  // namespace

void AddObjectCommands(CLI::App& app, std::shared_ptr<RemoteCli> cli) {
  CLI::App* object = app.add_subcommand("object", "Meshes to map: upload, list, show; rig registrations");
  object->require_subcommand(1);

  auto upload_args = std::make_shared<UploadArgs>();
  CLI::App* upload = object->add_subcommand(
      "upload", "Upload a mesh (.obj, .ply or .stl); prints its id, and repairs and warnings on stderr");
  upload->add_option("file", upload_args->file, "Mesh file")->required()->check(CLI::ExistingFile);
  upload->add_option("--name", upload_args->name, "Object name (default: the file name without extension)");
  upload->add_option("--units", upload_args->units, "The file's length unit: mm, cm, m or in (default: mm, unchecked)");
  upload->add_option("--scale", upload_args->scale, "mm per file unit (instead of --units)")
      ->check(CLI::PositiveNumber);
  upload->add_flag("--facets", upload_args->facets,
                   "The flat triangles are the object's surface (a CAD export: a box as 12 triangles); without it a "
                   "coarse mesh is a Loop control mesh, whose limit surface rounds edges and corners");
  AddProvenanceOptions(upload, &upload_args->provenance);
  upload->add_flag("--json", upload_args->json, "Print the ObjectInfo as JSON");
  upload->callback([cli, upload_args] { RunUpload(*cli, *upload_args); });

  auto list_json = std::make_shared<bool>(false);
  CLI::App* list = object->add_subcommand("list", "List objects");
  list->add_flag("--json", *list_json, "Print the response as JSON");
  list->callback([cli, list_json] {
    auto stub = pb::ObjectService::NewStub(cli->Channel());
    pb::ListObjectsResponse response;
    if (!CallRpc(*cli, "ListObjects", *stub, &pb::ObjectService::Stub::ListObjects, pb::ListObjectsRequest(),
                 &response)) {
      return;
    }
    if (*list_json) {
      std::printf("%s\n", MessageToJson(response).c_str());
    } else {
      PrintObjectTable(response.objects());
    }
  });

  auto show_id = std::make_shared<int64_t>(0);
  CLI::App* show = object->add_subcommand("show", "Show one object (JSON)");
  show->add_option("id", *show_id, "Object id")->required();
  show->callback([cli, show_id] {
    auto stub = pb::ObjectService::NewStub(cli->Channel());
    pb::GetObjectRequest request;
    request.set_object_id(*show_id);
    pb::GetObjectResponse response;
    if (!CallRpc(*cli, "GetObject", *stub, &pb::ObjectService::Stub::GetObject, request, &response)) return;
    std::printf("%s\n", MessageToJson(response.object()).c_str());
  });

  AddRegistrationCommands(*object, cli);
}

}  // namespace surfmap::cli
