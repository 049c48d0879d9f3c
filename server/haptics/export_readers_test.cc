// The PLY and glTF readers take files from outside: every count, index and
// type in them is checked, with an error naming what is wrong, before
// anything is allocated from it (no bad_alloc, no out-of-range read).
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "server/base/testing/status_matchers.h"
#include "server/haptics/test_meshes.h"
#include "server/haptics/texture_map_gltf.h"
#include "server/haptics/texture_map_ply.h"

namespace surfmap::haptics {
namespace {

using ::surfmap::status_matchers::IsOk;
using ::surfmap::status_matchers::StatusIs;
using ::testing::HasSubstr;

// A one-triangle PLY whose third vertex has region `region`.
std::string TrianglePly(const std::string& vertex_count, const std::string& region) {
  return absl::StrCat(
      "ply\nformat ascii 1.0\nelement vertex ", vertex_count,
      "\nproperty double x\nproperty double y\nproperty double z\nproperty double mu\nproperty double mu_std\n"
      "property int region\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 0.5 0.01 0\n1 0 0 0.5 0.01 0\n0 1 0 0.5 0.01 ",
      region, "\n3 0 1 2\n");
}

TEST(PlyReaderTest, ReadsTheSmallTriangle) {
  absl::StatusOr<TextureMap> map = ReadTexturePly(TrianglePly("3", "-1"), "t.ply");
  ASSERT_THAT(map, IsOk());
  EXPECT_EQ(map->vertex_count(), 3);
  EXPECT_EQ(map->region, (std::vector<int>{0, 0, -1}));
  EXPECT_EQ(map->regions.size(), 1u);
}

// 99999999999 vertices would be ~10 TB of positions: refused from the line
// count (3 vertex lines + 1 face line follow the header), not allocated.
TEST(PlyReaderTest, RefusesCountsBeyondTheLinesPresent) {
  EXPECT_THAT(ReadTexturePly(TrianglePly("99999999999", "0"), "big.ply"),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("99999999999 vertices")));
  // One more vertex than there are lines for (the face line would be read as one).
  EXPECT_THAT(ReadTexturePly(TrianglePly("5", "0"), "short.ply"),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("lines follow")));
}

// A region index must be -1 (unassigned) or a vertex-count-bounded index:
// 2147483647 would resize the region table to INT_MAX + 1 entries.
TEST(PlyReaderTest, RefusesRegionsOutsideTheVertexRange) {
  for (const char* region : {"2147483647", "3", "-2", "1e300"}) {
    EXPECT_THAT(ReadTexturePly(TrianglePly("3", region), "r.ply"),
                StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("outside -1..2")))
        << region;
  }
  EXPECT_THAT(ReadTexturePly(TrianglePly("3", "2"), "r.ply"), IsOk());
}

TextureMap SmallMap() {
  TextureMap map = testing::Sphere(15.0, 4, 6);
  testing::PaintSplit(map, 2.0, testing::kRubber, testing::kMasonite);
  return map;
}

// The written .gltf (JSON with an embedded buffer) as JSON to edit.
nlohmann::json GltfJson(const TextureMap& map) {
  absl::StatusOr<std::string> text = WriteTextureGltf(map, /*binary=*/false);
  EXPECT_THAT(text, IsOk());
  return nlohmann::json::parse(*text);
}

absl::StatusOr<TextureMap> ReadJson(const nlohmann::json& gltf) { return ReadTextureGltf(gltf.dump(), "edited.gltf"); }

int AttributeAccessor(const nlohmann::json& gltf, const char* name) {
  return gltf["meshes"][0]["primitives"][0]["attributes"][name].get<int>();
}

TEST(GltfReaderTest, UneditedFileReads) { EXPECT_THAT(ReadJson(GltfJson(SmallMap())), IsOk()); }

// An accessor without a bufferView (tinygltf gives -1) or with one that does
// not exist, and a view naming a missing buffer.
TEST(GltfReaderTest, RefusesMissingBufferViewsAndBuffers) {
  const nlohmann::json base = GltfJson(SmallMap());
  const int position = AttributeAccessor(base, "POSITION");
  nlohmann::json no_view = base;
  no_view["accessors"][position].erase("bufferView");
  EXPECT_THAT(ReadJson(no_view), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("bufferView -1")));
  nlohmann::json far_view = base;
  far_view["accessors"][position]["bufferView"] = 999;
  EXPECT_FALSE(ReadJson(far_view).ok());
  nlohmann::json far_buffer = base;
  far_buffer["bufferViews"][base["accessors"][position]["bufferView"].get<int>()]["buffer"] = 7;
  EXPECT_FALSE(ReadJson(far_buffer).ok());
}

// count * 12 bytes wraps to 0 for count = 2^62 (the old size check passed and
// the resize threw); the count is now checked against the view's bytes.
TEST(GltfReaderTest, RefusesCountsThatOverflowTheByteSize) {
  nlohmann::json gltf = GltfJson(SmallMap());
  const int position = AttributeAccessor(gltf, "POSITION");
  gltf["accessors"][position]["count"] = std::uint64_t{1} << 62;
  EXPECT_THAT(ReadJson(gltf), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("run past")));
}

TEST(GltfReaderTest, RefusesWrongComponentTypesAndStrides) {
  const nlohmann::json base = GltfJson(SmallMap());
  nlohmann::json bytes_mu = base;
  bytes_mu["accessors"][AttributeAccessor(base, "_MU")]["componentType"] = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  EXPECT_THAT(ReadJson(bytes_mu), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("_MU (accessor")));
  // A stride of 16 for 12-byte positions is legal glTF; this view then holds
  // fewer positions than the accessor claims, which the reader must notice
  // (it used to read the bytes as if tightly packed).
  nlohmann::json strided = base;
  const int view = base["accessors"][AttributeAccessor(base, "POSITION")]["bufferView"].get<int>();
  strided["bufferViews"][view]["byteStride"] = 16;
  EXPECT_THAT(ReadJson(strided), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("run past")));
}

// Metadata of the wrong type: an error, not nlohmann::type_error.
TEST(GltfReaderTest, RefusesMistypedMetadata) {
  const nlohmann::json base = GltfJson(SmallMap());
  auto with = [&](const char* key, const nlohmann::json& value) {
    nlohmann::json gltf = base;
    gltf["meshes"][0]["extras"]["surfmap"][key] = value;
    return ReadJson(gltf);
  };
  EXPECT_THAT(with("level", "three"), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("level")));
  EXPECT_THAT(with("job_id", "forty-two"), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("job_id")));
  EXPECT_THAT(with("grid_step_mm", "fine"), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("grid_step_mm")));
  EXPECT_THAT(with("format", 3), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("format")));
  // A negative order used to size the reflection array as n * -5 (a huge size_t).
  EXPECT_THAT(with("ar_order", -5), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("ar_order")));
  EXPECT_THAT(with("ar_order", 1000000000), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("ar_order")));
}

// 16-bit indices (what most glTF tools write for small meshes) read as the
// same triangles; they used to be read as 32-bit garbage.
TEST(GltfReaderTest, ReadsSixteenBitIndices) {
  const TextureMap map = SmallMap();
  tinygltf::Model model;
  tinygltf::TinyGLTF gltf;
  std::string err, warn;
  const std::string text = *WriteTextureGltf(map, /*binary=*/false);
  ASSERT_TRUE(gltf.LoadASCIIFromString(&model, &err, &warn, text.data(), static_cast<unsigned>(text.size()), ""))
      << err;
  std::vector<unsigned char>& buffer = model.buffers[0].data;
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.size();
  for (const auto& t : map.triangles) {
    for (int c : t) {
      const auto i16 = static_cast<std::uint16_t>(c);
      unsigned char b[2];
      std::memcpy(b, &i16, 2);
      buffer.insert(buffer.end(), b, b + 2);
    }
  }
  view.byteLength = buffer.size() - view.byteOffset;
  buffer.resize((buffer.size() + 3) / 4 * 4, 0);
  model.bufferViews.push_back(view);
  tinygltf::Accessor acc;
  acc.bufferView = static_cast<int>(model.bufferViews.size()) - 1;
  acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
  acc.type = TINYGLTF_TYPE_SCALAR;
  acc.count = 3 * map.triangles.size();
  model.accessors.push_back(acc);
  model.meshes[0].primitives[0].indices = static_cast<int>(model.accessors.size()) - 1;
  std::ostringstream out;
  ASSERT_TRUE(gltf.WriteGltfSceneToStream(&model, out, false, false));
  absl::StatusOr<TextureMap> back = ReadTextureGltf(out.str(), "u16.gltf");
  ASSERT_THAT(back, IsOk());
  EXPECT_EQ(back->triangles, map.triangles);
}

}  // namespace
}  // namespace surfmap::haptics
