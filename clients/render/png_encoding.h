// PNG encoding of an RgbImage into memory (stb_image_write).
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "clients/render/rgb_image.h"

namespace surfmap {

// The PNG file bytes. Errors: INVALID_ARGUMENT for an empty image or a pixel
// buffer of the wrong size; INTERNAL if the encoder fails.
absl::StatusOr<std::string> EncodePng(const RgbImage& image);

}  // namespace surfmap
