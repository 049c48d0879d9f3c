// The simulated rig behind the external driver protocol: `surfmap-rig
// simulate-drag --sim SCENE` reads command lines on stdin and answers each
// with the trace SimulatedRig measures (or a failure), as a real driver
// program would. So the protocol can be tried without a robot
// (`surfmap-rig --driver "surfmap-rig simulate-drag --sim plate"`), and a
// lab's driver skeleton can send its "hardware" calls to the simulator
// (clients/python/examples/arm_driver.py --simulate).
#pragma once

#include <iosfwd>
#include <string_view>

#include "clients/sim/rig/rig_driver.h"

namespace surfmap::rig {

// Writes the ready line naming `name`, then answers every command line of
// `in` on `out` (flushed per line) until end of input: 0. A line that is not
// a valid command: the problem on `errors` ("stdin line 3: ...") and 2 (the
// rig reports its command as failed and stops: a protocol error).
int ServeSimulatedDriver(RigDriver& rig, std::string_view name, std::istream& in, std::ostream& out,
                         std::ostream& errors);

}  // namespace surfmap::rig
