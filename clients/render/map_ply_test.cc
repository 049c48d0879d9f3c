#include "clients/render/map_ply.h"

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

// A unit square (two triangles) with mu 0.1 .. 0.5 and one unknown vertex.
MapMesh Square() {
  MapMesh m;
  m.positions = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.values = {0.1, 0.5, 0.3, std::nan("")};
  m.uncertainties = {0.01, 0.02, 0.03, 0.04};
  return m;
}

struct ParsedPly {
  std::vector<std::string> properties;
  int vertices = -1;
  int faces = -1;
  std::vector<std::vector<std::string>> vertex_rows;
  std::vector<std::vector<int>> face_rows;
};

ParsedPly Parse(const std::string& text) {
  ParsedPly out;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "ply");
  std::getline(in, line);
  EXPECT_EQ(line, "format ascii 1.0");
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream words(line);
    std::string kind;
    words >> kind;
    if (kind == "element") {
      std::string name;
      int count;
      words >> name >> count;
      (name == "vertex" ? out.vertices : out.faces) = count;
    } else if (kind == "property") {
      std::string type, name;
      words >> type;
      if (type == "list") {
        std::string count_type, index_type;
        words >> count_type >> index_type;
      }
      words >> name;
      out.properties.push_back(name);
    }
  }
  for (int i = 0; i < out.vertices && std::getline(in, line); ++i) {
    std::istringstream words(line);
    std::vector<std::string> row;
    for (std::string w; words >> w;) row.push_back(w);
    out.vertex_rows.push_back(row);
  }
  for (int i = 0; i < out.faces && std::getline(in, line); ++i) {
    std::istringstream words(line);
    std::vector<int> row;
    for (int v; words >> v;) row.push_back(v);
    out.face_rows.push_back(row);
  }
  EXPECT_FALSE(std::getline(in, line) && !line.empty()) << "trailing data: " << line;
  return out;
}

TEST(WriteMapPlyTest, HeaderAndCountsParseBack) {
  auto ply = WriteMapPly(Square());
  ASSERT_TRUE(ply.ok()) << ply.status();
  const ParsedPly p = Parse(*ply);
  EXPECT_EQ(p.vertices, 4);
  EXPECT_EQ(p.faces, 2);
  EXPECT_EQ(p.properties, (std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz", "mu", "mu_std", "red", "green",
                                                    "blue", "vertex_indices"}));
  ASSERT_EQ(p.vertex_rows.size(), 4u);
  for (const auto& row : p.vertex_rows) EXPECT_EQ(row.size(), 11u);
  ASSERT_EQ(p.face_rows.size(), 2u);
  EXPECT_EQ(p.face_rows[1], (std::vector<int>{3, 0, 2, 3}));
}

TEST(WriteMapPlyTest, ValuesNormalsAndColoursRoundTrip) {
  auto ply = WriteMapPly(Square());
  ASSERT_TRUE(ply.ok());
  const ParsedPly p = Parse(*ply);
  EXPECT_NEAR(std::stod(p.vertex_rows[1][0]), 10.0, 1e-6);
  EXPECT_NEAR(std::stod(p.vertex_rows[1][6]), 0.5, 1e-7);
  EXPECT_NEAR(std::stod(p.vertex_rows[2][7]), 0.03, 1e-7);
  EXPECT_NEAR(std::stod(p.vertex_rows[0][5]), 1.0, 1e-7);  // computed normal of a CCW square: +z
  EXPECT_EQ(p.vertex_rows[3][6], "nan");
  // Grey over [0.1, 0.5]: min dark grey, max white, 0.3 half-way, unknown = no-data colour.
  EXPECT_EQ(p.vertex_rows[0][8], "40");
  EXPECT_EQ(p.vertex_rows[1][8], "255");
  EXPECT_NEAR(std::stoi(p.vertex_rows[2][9]), 147.5, 0.6);
  EXPECT_EQ(p.vertex_rows[3][8], "170");
}

TEST(WriteMapPlyTest, ExplicitRangeAndComment) {
  MapPlyOptions o;
  o.value_min = 0.0;
  o.value_max = 1.0;
  o.comment = "bottle\nlevel 3";
  auto ply = WriteMapPly(Square(), o);
  ASSERT_TRUE(ply.ok());
  EXPECT_NE(ply->find("comment bottle level 3\n"), std::string::npos);
  const ParsedPly p = Parse(*ply);
  EXPECT_NEAR(std::stoi(p.vertex_rows[1][8]), 147.5, 0.6);  // 0.5 of [0, 1]
}

TEST(WriteMapPlyTest, RejectsInvalidMesh) {
  MapMesh m = Square();
  m.uncertainties.pop_back();
  auto ply = WriteMapPly(m);
  EXPECT_EQ(ply.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(ply.status().message().find("uncertainties"), std::string::npos) << ply.status();
  MapPlyOptions o;
  o.value_min = 2;
  o.value_max = 1;
  EXPECT_FALSE(WriteMapPly(Square(), o).ok());
}

}  // namespace
}  // namespace surfmap
