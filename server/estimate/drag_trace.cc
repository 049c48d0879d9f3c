#include "server/estimate/drag_trace.h"

namespace surfmap {

std::string_view DragPhaseName(DragPhase phase) {
  switch (phase) {
    case DragPhase::kForward: return "fwd";
    case DragPhase::kPause: return "pause";
    case DragPhase::kReverse: return "rev";
  }
  return "?";
}

}  // namespace surfmap
