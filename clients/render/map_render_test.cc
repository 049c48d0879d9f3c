#include "clients/render/map_render.h"

#include <cmath>
#include <numbers>
#include <string>

#include <gtest/gtest.h>
#include "clients/render/png_encoding.h"

#define STBI_ONLY_PNG
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include "stb_image.h"
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace surfmap {
namespace {

// A UV sphere of radius r at the origin; value = `upper` for z > 0 else `lower`.
MapMesh Sphere(double r, double upper, double lower, int stacks = 24, int slices = 48) {
  MapMesh m;
  m.positions.push_back({0, 0, -r});
  for (int i = 1; i < stacks; ++i) {
    const double phi = -std::numbers::pi / 2 + std::numbers::pi * i / stacks;
    for (int j = 0; j < slices; ++j) {
      const double th = 2 * std::numbers::pi * j / slices;
      m.positions.push_back({r * std::cos(phi) * std::cos(th), r * std::cos(phi) * std::sin(th), r * std::sin(phi)});
    }
  }
  m.positions.push_back({0, 0, r});
  const int top = static_cast<int>(m.positions.size()) - 1;
  auto ring = [&](int i, int j) { return 1 + (i - 1) * slices + (j % slices); };
  for (int j = 0; j < slices; ++j) m.triangles.push_back({0, ring(1, j + 1), ring(1, j)});
  for (int i = 1; i + 1 < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      m.triangles.push_back({ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)});
      m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)});
    }
  }
  for (int j = 0; j < slices; ++j) m.triangles.push_back({top, ring(stacks - 1, j), ring(stacks - 1, j + 1)});
  for (const auto& p : m.positions) {
    m.normals.push_back(p.normalized());
    m.values.push_back(p.z() > 1e-9 ? upper : lower);
  }
  return m;
}

int Brightness(Rgb c) { return c[0] + c[1] + c[2]; }

MapRenderOptions SingleView() {
  MapRenderOptions o;
  o.view_width = 200;
  o.view_height = 160;
  o.two_views = false;
  o.color_bar = false;
  return o;
}

TEST(RenderMapTest, ImageSizeCoversViewsAndColorBar) {
  MapRenderOptions o;
  o.view_width = 120;
  o.view_height = 100;
  auto image = RenderMap(Sphere(10, 0.5, 0.1), {}, o);
  ASSERT_TRUE(image.ok()) << image.status();
  EXPECT_EQ(image->width, 2 * 120 + kColorBarStripWidth);
  EXPECT_EQ(image->height, 100);
  EXPECT_EQ(image->pixels.size(), static_cast<size_t>(image->width) * 100 * 3);
  o.two_views = false;
  o.color_bar = false;
  image = RenderMap(Sphere(10, 0.5, 0.1), {}, o);
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(image->width, 120);
}

TEST(RenderMapTest, ObjectDiffersFromBackground) {
  const MapRenderOptions o = SingleView();
  auto image = RenderMap(Sphere(10, 0.3, 0.3), {}, o);
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(image->At(0, 0), o.background);
  EXPECT_EQ(image->At(199, 159), o.background);
  EXPECT_NE(image->At(100, 80), o.background);
  // The sphere is framed with a margin: its silhouette spans most of the short side.
  int covered = 0;
  for (int x = 0; x < 200; ++x) covered += image->At(x, 80) != o.background;
  EXPECT_GT(covered, 60);
  EXPECT_LT(covered, 160);
}

TEST(RenderMapTest, HigherFrictionIsBrighterInGrey) {
  const MapRenderOptions o = SingleView();
  auto image = RenderMap(Sphere(10, /*upper=*/0.5, /*lower=*/0.13), {}, o);
  ASSERT_TRUE(image.ok());
  // Mirror-symmetric pixels above and below the equator: same shading, different mu.
  for (int dy : {10, 20, 30}) {
    const Rgb up = image->At(100, 80 - dy);
    const Rgb down = image->At(100, 79 + dy);
    EXPECT_GT(Brightness(up), Brightness(down) + 300) << "dy " << dy;
    EXPECT_EQ(up[0], up[1]);  // grey
  }
}

TEST(RenderMapTest, ShadingDarkensTowardsTheSilhouette) {
  const MapRenderOptions o = SingleView();
  auto image = RenderMap(Sphere(10, 0.5, 0.5), {}, o);
  ASSERT_TRUE(image.ok());
  int edge = 0;
  while (image->At(edge, 80) == o.background) ++edge;
  EXPECT_GT(Brightness(image->At(100, 80)), Brightness(image->At(edge + 1, 80)) + 100);
}

TEST(RenderMapTest, HiddenSamplePointsAreNotDrawn) {
  MapRenderOptions o = SingleView();  // looks along +y: the front of the sphere is y = -10
  MapOverlay front{{Eigen::Vector3d(0, -10, 0)}, {}};
  MapOverlay back{{Eigen::Vector3d(0, 10, 0)}, {}};
  auto with_front = RenderMap(Sphere(10, 0.3, 0.3), front, o);
  auto with_back = RenderMap(Sphere(10, 0.3, 0.3), back, o);
  ASSERT_TRUE(with_front.ok());
  ASSERT_TRUE(with_back.ok());
  EXPECT_EQ(with_front->At(100, 80), o.sample_color);
  EXPECT_NE(with_back->At(100, 80), o.sample_color);
  // The second view looks from the other side and shows it.
  o.two_views = true;
  auto both = RenderMap(Sphere(10, 0.3, 0.3), back, o);
  ASSERT_TRUE(both.ok());
  EXPECT_NE(both->At(100, 80), o.sample_color);
  EXPECT_EQ(both->At(200 + 100, 80), o.sample_color);
}

TEST(RenderMapTest, DragPathsAreDepthTested) {
  const MapRenderOptions o = SingleView();
  // A horizontal arc over the front at the equator, and the same over the back.
  auto arc = [](double y_sign) {
    std::vector<Eigen::Vector3d> path;
    for (int i = -5; i <= 5; ++i) {
      const double a = 0.05 * i;
      path.push_back({10 * std::sin(a), y_sign * 10 * std::cos(a), 0});
    }
    return path;
  };
  auto front = RenderMap(Sphere(10, 0.3, 0.3), MapOverlay{{}, {arc(-1)}}, o);
  auto back = RenderMap(Sphere(10, 0.3, 0.3), MapOverlay{{}, {arc(+1)}}, o);
  ASSERT_TRUE(front.ok());
  ASSERT_TRUE(back.ok());
  int front_hits = 0, back_hits = 0;
  for (int x = 80; x < 120; ++x) {
    for (int y = 78; y <= 82; ++y) {
      front_hits += front->At(x, y) == o.path_color;
      back_hits += back->At(x, y) == o.path_color;
    }
  }
  EXPECT_GT(front_hits, 20);
  EXPECT_EQ(back_hits, 0);
}

TEST(RenderMapTest, UnknownValuesUseNoDataColor) {
  MapMesh m = Sphere(10, 0.3, 0.3);
  for (double& v : m.values) v = std::nan("");
  const MapRenderOptions o = SingleView();
  auto image = RenderMap(m, {}, o);
  ASSERT_TRUE(image.ok());
  const Rgb c = image->At(100, 80);  // faces the camera: full no-data colour
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(c[i], o.no_data_color[i], 3);
}

TEST(RenderMapTest, ColorBarRunsFromMinAtTheBottomToMaxAtTheTop) {
  MapRenderOptions o;
  o.view_width = 100;
  o.view_height = 200;
  o.two_views = false;
  auto image = RenderMap(Sphere(10, 0.5, 0.1), {}, o);
  ASSERT_TRUE(image.ok());
  const int x = 100 + kColorBarStripWidth / 2;
  EXPECT_GT(Brightness(image->At(x, 40)), 700);  // near white at the top
  EXPECT_LT(Brightness(image->At(x, 160)), 3 * 60);  // dark grey at the bottom
  // Labels are drawn in the label colour above the bar.
  int label_pixels = 0;
  for (int y = 0; y < 30; ++y) {
    for (int xx = 100; xx < image->width; ++xx) label_pixels += image->At(xx, y) == o.label_color;
  }
  EXPECT_GT(label_pixels, 20);
}

// A title goes above the labels, in the label colour; without one the max
// label starts at row 12, so rows 8..11 (the title's top four rows) are empty.
TEST(RenderMapTest, ColorBarTitleIsDrawnAboveTheLabels) {
  MapRenderOptions o;
  o.view_width = 100;
  o.view_height = 200;
  o.two_views = false;
  auto count_title_pixels = [&](const RgbImage& image) {
    int n = 0;
    for (int y = 8; y < 12; ++y) {
      for (int x = 100; x < image.width; ++x) n += image.At(x, y) == o.label_color;
    }
    return n;
  };
  auto plain = RenderMap(Sphere(10, 0.5, 0.1), {}, o);
  o.color_bar_title = "SIGMA (N)";
  auto titled = RenderMap(Sphere(10, 0.5, 0.1), {}, o);
  ASSERT_TRUE(plain.ok() && titled.ok());
  EXPECT_EQ(count_title_pixels(*plain), 0);
  // "SIGMA (N)": the top four rows of its 8 glyphs light dozens of pixels.
  EXPECT_GT(count_title_pixels(*titled), 20);
}

TEST(RenderMapTest, ViridisColoursTheObject) {
  MapRenderOptions o = SingleView();
  o.color_map = ColorMap::kViridis;
  auto image = RenderMap(Sphere(10, 0.5, 0.1), {}, o);
  ASSERT_TRUE(image.ok());
  const Rgb high = image->At(100, 60);  // yellowish: red+green >> blue
  const Rgb low = image->At(100, 99);   // purple: blue > green
  EXPECT_GT(high[1], high[2] + 50);
  EXPECT_GT(low[2], low[1]);
}

TEST(RenderMapTest, PerspectiveViewRendersTheObject) {
  MapRenderOptions o = SingleView();
  o.perspective = true;
  o.fov_deg = 40;
  auto image = RenderMap(Sphere(10, 0.3, 0.3), {}, o);
  ASSERT_TRUE(image.ok());
  EXPECT_NE(image->At(100, 80), o.background);
  EXPECT_EQ(image->At(2, 2), o.background);
}

TEST(RenderMapTest, RejectsBadInput) {
  MapMesh m = Sphere(10, 0.3, 0.3);
  m.values.pop_back();
  auto r = RenderMap(m, {}, SingleView());
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("values"), std::string::npos) << r.status();

  m = Sphere(10, 0.3, 0.3);
  m.triangles[5][1] = 100000;
  r = RenderMap(m, {}, SingleView());
  EXPECT_NE(r.status().message().find("triangle 5"), std::string::npos) << r.status();

  MapRenderOptions o = SingleView();
  o.view_width = 3;
  r = RenderMap(Sphere(10, 0.3, 0.3), {}, o);
  EXPECT_NE(r.status().message().find("view_width"), std::string::npos) << r.status();

  o = SingleView();
  o.value_min = 1.0;
  o.value_max = 0.5;
  EXPECT_FALSE(RenderMap(Sphere(10, 0.3, 0.3), {}, o).ok());

  MapOverlay bad{{Eigen::Vector3d(0, std::nan(""), 0)}, {}};
  r = RenderMap(Sphere(10, 0.3, 0.3), bad, SingleView());
  EXPECT_NE(r.status().message().find("sample point 0"), std::string::npos) << r.status();
}

TEST(RenderMapPngTest, PngDecodesToTheRenderedPixels) {
  MapRenderOptions o;
  o.view_width = 64;
  o.view_height = 48;
  const MapMesh m = Sphere(10, 0.5, 0.1);
  auto image = RenderMap(m, {}, o);
  auto png = RenderMapPng(m, {}, o);
  ASSERT_TRUE(image.ok());
  ASSERT_TRUE(png.ok()) << png.status();
  ASSERT_GT(png->size(), 8u);
  EXPECT_EQ(png->substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  int w = 0, h = 0, channels = 0;
  unsigned char* decoded = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(png->data()),
                                                 static_cast<int>(png->size()), &w, &h, &channels, 3);
  ASSERT_NE(decoded, nullptr);
  EXPECT_EQ(w, image->width);
  EXPECT_EQ(h, image->height);
  EXPECT_TRUE(std::equal(image->pixels.begin(), image->pixels.end(), decoded));
  stbi_image_free(decoded);
}

TEST(RenderMapPngTest, EncodeRejectsInconsistentImage) {
  RgbImage bad;
  bad.width = 4;
  bad.height = 4;
  bad.pixels.resize(5);
  EXPECT_EQ(EncodePng(bad).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(EncodePng(RgbImage()).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace surfmap
