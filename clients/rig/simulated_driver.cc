#include "clients/rig/simulated_driver.h"

#include <istream>
#include <ostream>
#include <string>

#include "absl/strings/str_cat.h"
#include "clients/rig/driver_protocol.h"
#include "clients/rig/rig_loop.h"

namespace surfmap::rig {

int ServeSimulatedDriver(RigDriver& rig, std::string_view name, std::istream& in, std::ostream& out,
                         std::ostream& errors) {
  out << FormatReadyMessage(name) << '\n' << std::flush;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    absl::StatusOr<ProbeRequest> request = ParseCommandMessage(line);
    if (!request.ok()) {
      errors << "surfmap-rig simulate-drag: stdin line " << number << ": " << request.status().message() << '\n';
      return 2;
    }
    absl::StatusOr<DragTrace> trace = rig.Execute(*request);
    if (trace.ok()) {
      out << FormatTraceMessage(request->command_id, *trace) << '\n' << std::flush;
    } else {
      out << FormatFailureMessage(request->command_id, FailureKindOf(trace.status()),
                                  absl::StrCat("simulated rig: ", trace.status().message()))
          << '\n'
          << std::flush;
    }
  }
  return 0;
}

}  // namespace surfmap::rig
