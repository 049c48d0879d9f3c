#include "clients/cli/map_regions_command.h"

#include <cstdio>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "clients/cli/number_text.h"
#include "proto/surfmap/v1/surfmap.grpc.pb.h"

namespace surfmap::cli {
namespace {

namespace pb = ::surfmap::v1;

struct MapRegionsArgs {
  int64_t job_id = 0;
  int region = -1;  // -1: every region
  bool pieces = false;
  bool json = false;
};

void PrintRegion(const pb::MapRegion& r) {
  const std::string roughness = r.ar_coefficients_size() >= 2
                                    ? absl::StrFormat("%.2f / %.2f / %.3f", Shown(r.ar_coefficients(0), 2),
                                                      Shown(r.ar_coefficients(1), 2), r.sigma())
                                    : "-";
  std::printf("%6d %8d %7.4f %7.4f %7.4f %6d %9.1f  %s\n", r.region(), r.material(), Shown(r.mu(), 4),
              Shown(r.mu_se(), 4), Shown(r.own_mu(), 4), r.piece_count(), Shown(r.area_mm2(), 1),
              roughness.c_str());
}

void PrintPieces(const pb::MapRegion& r) {
  std::printf("       %8s %5s %7s %7s %7s %7s %6s %6s\n", "trace", "piece", "from_mm", "to_mm", "mu", "mu_se",
              "pairs", "weight");
  for (const pb::MapRegionPiece& p : r.pieces()) {
    const std::string piece = absl::StrCat(p.fit_piece(), p.split_by_map() ? "*" : "");
    const std::string weight = p.in_mu() ? absl::StrFormat("%6.3f", p.mu_weight()) : "     -";
    std::printf("       %8lld %5s %7.2f %7.2f %7.4f %7.4f %6.1f %s\n", static_cast<long long>(p.trace_id()),
                piece.c_str(), Shown(p.start_mm(), 2), Shown(p.end_mm(), 2), Shown(p.mu(), 4), Shown(p.mu_se(), 4),
                p.effective_pairs(), weight.c_str());
  }
}

void RunMapRegions(RemoteCli& cli, const MapRegionsArgs& args) {
  auto stub = pb::MapService::NewStub(cli.Channel());
  pb::GetMapRequest request;
  request.set_job_id(args.job_id);
  request.set_level(-1);
  pb::GetMapResponse response;
  if (!CallRpc(cli, "GetMap", *stub, &pb::MapService::Stub::GetMap, request, &response)) return;
  const pb::MapLevel& map = response.map();
  if (args.region >= map.regions_size()) {
    return FailUsage(cli, absl::StrCat("--region ", args.region, ": job ", args.job_id, "'s map has ",
                                       map.regions_size(), " regions (0..", map.regions_size() - 1, ")"));
  }
  if (args.json) {
    // An array of MapRegion, as GetMap has them (proto field names).
    std::string out = "[";
    for (const pb::MapRegion& r : map.regions()) {
      if (args.region >= 0 && r.region() != args.region) continue;
      absl::StrAppend(&out, out.size() > 1 ? ",\n" : "\n", MessageToJson(r));
    }
    std::printf("%s\n]\n", out.c_str());
    return;
  }
  if (map.regions_size() == 0) {
    std::printf("job %lld has no map yet (no drag measured)\n", static_cast<long long>(args.job_id));
    return;
  }
  std::printf("%6s %8s %7s %7s %7s %6s %9s  %s\n", "region", "material", "mu", "mu_se", "own_mu", "pieces",
              "area_mm2", "a1 / a2 / sigma");
  for (const pb::MapRegion& r : map.regions()) {
    if (args.region >= 0 && r.region() != args.region) continue;
    PrintRegion(r);
    if (args.pieces) PrintPieces(r);
  }
  if (args.pieces) {
    std::printf("piece: of the trace's fit (* = a part the map cut where it found a change)\n"
                "weight: share of the material's mu; - = not counted: under 4 mm where the\n"
                "  material has enough longer pieces, or its series fit the material of the\n"
                "  region it was grouped in worse than another's (it is then moved to a region\n"
                "  of its own of that other material), or it was of a material that two others\n"
                "  explained as pieces straddling their boundary (dissolved into them)\n");
  }
}

}  // namespace

void AddMapRegionsCommand(CLI::App& map, std::shared_ptr<RemoteCli> cli) {
  auto a = std::make_shared<MapRegionsArgs>();
  CLI::App* regions = map.add_subcommand(
      "regions", "A job's material regions: mu, its error, roughness; --pieces: the drag pieces behind each");
  regions->add_option("job", a->job_id, "Job id")->required();
  regions->add_option("--region", a->region, "Only this region (its index)")->check(CLI::NonNegativeNumber);
  regions->add_flag("--pieces", a->pieces, "Also each region's drag pieces and their weight in its mu");
  regions->add_flag("--json", a->json, "Print the regions (with their pieces) as JSON");
  regions->callback([cli, a] { RunMapRegions(*cli, *a); });
}

}  // namespace surfmap::cli
