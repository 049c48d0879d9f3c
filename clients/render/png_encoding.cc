#include "clients/render/png_encoding.h"

#include "absl/strings/str_cat.h"

// The only translation unit that compiles stb_image_write. STATIC keeps its
// symbols private, so this cannot clash with Debian's libstb or other users.
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
#include "stb_image_write.h"
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace surfmap {
namespace {

void AppendBytes(void* context, void* data, int size) {
  static_cast<std::string*>(context)->append(static_cast<const char*>(data), static_cast<size_t>(size));
}

}  // namespace

absl::StatusOr<std::string> EncodePng(const RgbImage& image) {
  if (image.width <= 0 || image.height <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("cannot encode an empty image (", image.width, " x ", image.height, ")"));
  }
  const size_t expected = static_cast<size_t>(image.width) * image.height * 3;
  if (image.pixels.size() != expected) {
    return absl::InvalidArgumentError(absl::StrCat("image buffer holds ", image.pixels.size(), " bytes, ",
                                                   image.width, " x ", image.height, " RGB needs ", expected));
  }
  std::string out;
  const int ok = stbi_write_png_to_func(&AppendBytes, &out, image.width, image.height, 3, image.pixels.data(),
                                        image.width * 3);
  if (ok == 0) return absl::InternalError("stb_image_write failed to encode the PNG");
  return out;
}

}  // namespace surfmap
