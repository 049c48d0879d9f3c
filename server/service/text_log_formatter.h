// The text log format: "<time> <level> <message>", with the message escaped
// (server/base/utf8_text.h) so that text from a client (an object name, a rig
// id, a failure reason, an error quoting them) can never start a line of its
// own and forge a record.
#pragma once

#include <memory>

#include <spdlog/formatter.h>

namespace surfmap {

std::unique_ptr<spdlog::formatter> MakeTextLogFormatter();

}  // namespace surfmap
