#include "splat/ply.h"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <random>

#include "splat/error.h"
#include "tests/test_util.h"

namespace splat {
namespace {

using testing_util::read_file;
using testing_util::TempDir;
using testing_util::write_file;

GaussianModel random_model(size_t n, bool op2gs, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g;
  GaussianModel m;
  m.resize(n);
  for (auto* v : {&m.means, &m.sh_dc, &m.sh_rest, &m.opacity_logits, &m.log_scales, &m.rotations,
                  &m.instance_opacity_logits})
    for (float& x : *v) x = g(rng);
  for (size_t i = 0; i < n; ++i) m.labels[i] = int32_t(i % 7);
  m.has_instance_opacity = m.has_labels = op2gs;
  if (!op2gs) {
    std::fill(m.instance_opacity_logits.begin(), m.instance_opacity_logits.end(), 0.f);
    std::fill(m.labels.begin(), m.labels.end(), 0);
  }
  return m;
}

// The reader (read_gaussian_ply by default) refuses the file, naming it and
// saying why_part.
template <typename Reader = GaussianModel (*)(const std::filesystem::path&)>
void expect_ply_rejected(const std::filesystem::path& file, const std::string& why_part,
                         Reader read = read_gaussian_ply) {
  try {
    read(file);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file.filename().string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(why_part), std::string::npos) << msg;
  }
}

TEST(Ply, RoundTripWithOp2gsProperties) {
  TempDir dir;
  const GaussianModel m = random_model(1000, true);
  write_gaussian_ply(dir / "m.ply", m);
  EXPECT_EQ(read_gaussian_ply(dir / "m.ply"), m);
}

TEST(Ply, RoundTripWithoutOp2gsProperties) {
  TempDir dir;
  const GaussianModel m = random_model(100, false);
  write_gaussian_ply(dir / "m.ply", m);
  const GaussianModel back = read_gaussian_ply(dir / "m.ply");
  EXPECT_FALSE(back.has_labels);
  EXPECT_FALSE(back.has_instance_opacity);
  EXPECT_EQ(back, m);
}

TEST(Ply, HeaderIsTheStandardLayout) {
  TempDir dir;
  write_gaussian_ply(dir / "m.ply", random_model(2, true));
  const std::string bytes = read_file(dir / "m.ply");
  const std::string header = bytes.substr(0, bytes.find("end_header"));
  std::string expected = "ply\nformat binary_little_endian 1.0\nelement vertex 2\n";
  for (const char* p : {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"})
    expected += std::string("property float ") + p + "\n";
  for (int k = 0; k < 45; ++k) expected += "property float f_rest_" + std::to_string(k) + "\n";
  for (const char* p : {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2",
                        "rot_3", "instance_opacity"})
    expected += std::string("property float ") + p + "\n";
  expected += "property int label\n";
  EXPECT_EQ(header, expected);
  EXPECT_EQ(bytes.size(), header.size() + std::string("end_header\n").size() + 2 * (64 * 4));
}

TEST(Ply, FRestIsChannelMajorInTheFile) {
  TempDir dir;
  GaussianModel m;
  m.resize(1);
  // Coefficient 1 of green is index (coefficient 0, channel 1) in memory, and
  // f_rest_15 (green's first) in the file.
  m.sh_rest[3 * 0 + 1] = 42.f;
  write_gaussian_ply(dir / "m.ply", m);
  const std::string bytes = read_file(dir / "m.ply");
  const size_t data = bytes.find("end_header\n") + 11;
  float f;
  std::memcpy(&f, bytes.data() + data + 4 * (9 + 15), 4);
  EXPECT_EQ(f, 42.f);
}

// An ASCII file from another tool: SH degree 1 (9 f_rest), properties in
// another order, doubles, an extra property and no normals.
TEST(Ply, ReadsAsciiFromOtherToolsWithLowerShDegree) {
  TempDir dir;
  std::string text = "ply\nformat ascii 1.0\ncomment made by another tool\nelement vertex 2\n";
  for (const char* p : {"opacity", "x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2"})
    text += std::string("property double ") + p + "\n";
  for (int k = 0; k < 9; ++k) text += "property float f_rest_" + std::to_string(k) + "\n";
  for (const char* p :
       {"scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3", "filter_3D"})
    text += std::string("property float ") + p + "\n";
  text += "end_header\n";
  text += "0.5 1 2 3 0.1 0.2 0.3 1 2 3 4 5 6 7 8 9 -1 -2 -3 1 0 0 0 7\n";
  text += "-0.5 4 5 6 0 0 0 0 0 0 0 0 0 0 0 0 -4 -5 -6 0 1 0 0 7\n";
  write_file(dir / "a.ply", text);
  const GaussianModel m = read_gaussian_ply(dir / "a.ply");
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m.means[0], 1.f);
  EXPECT_EQ(m.means[5], 6.f);
  EXPECT_EQ(m.opacity_logits[0], 0.5f);
  EXPECT_FLOAT_EQ(m.sh_dc[2], 0.3f);
  // Degree 1: three coefficients per channel, channel-major in the file.
  EXPECT_EQ(m.sh_rest[3 * 0 + 0], 1.f);  // red, coefficient 1
  EXPECT_EQ(m.sh_rest[3 * 2 + 0], 3.f);  // red, coefficient 3
  EXPECT_EQ(m.sh_rest[3 * 0 + 1], 4.f);  // green, coefficient 1
  EXPECT_EQ(m.sh_rest[3 * 2 + 2], 9.f);  // blue, coefficient 3
  EXPECT_EQ(m.sh_rest[3 * 3 + 0], 0.f);  // degree 2+ absent: zero
  EXPECT_EQ(m.rotations[4], 0.f);
  EXPECT_EQ(m.rotations[5], 1.f);
  EXPECT_FALSE(m.has_labels);
}

TEST(Ply, ReadsLabelOfAnyIntegerType) {
  TempDir dir;
  std::string text = "ply\nformat ascii 1.0\nelement vertex 1\n";
  for (const char* p :
       {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2",
        "rot_0", "rot_1", "rot_2", "rot_3", "instance_opacity"})
    text += std::string("property float ") + p + "\n";
  text += "property ushort label\nend_header\n0 0 0 0 0 0 0 0 0 0 1 0 0 0 -2.5 513\n";
  write_file(dir / "a.ply", text);
  const GaussianModel m = read_gaussian_ply(dir / "a.ply");
  EXPECT_TRUE(m.has_labels);
  EXPECT_EQ(m.labels[0], 513);
  EXPECT_EQ(m.instance_opacity_logits[0], -2.5f);
}

TEST(Ply, TruncatedBinaryIsRejected) {
  TempDir dir;
  write_gaussian_ply(dir / "m.ply", random_model(10, true));
  const std::string bytes = read_file(dir / "m.ply");
  write_file(dir / "cut.ply", bytes.substr(0, bytes.size() - 5));
  expect_ply_rejected(dir / "cut.ply", "truncated");
  write_file(dir / "nohdr.ply", bytes.substr(0, bytes.find("property float opacity")));
  expect_ply_rejected(dir / "nohdr.ply", "end_header");
}

TEST(Ply, LyingVertexCountIsRejected) {
  TempDir dir;
  write_gaussian_ply(dir / "m.ply", random_model(3, false));
  std::string bytes = read_file(dir / "m.ply");
  bytes.replace(bytes.find("vertex 3"), 8, "vertex 9999999999");
  write_file(dir / "m.ply", bytes);
  expect_ply_rejected(dir / "m.ply", "truncated");
}

TEST(Ply, NanOrInfiniteParametersAreCounted) {
  TempDir dir;
  GaussianModel m = random_model(10, true);
  m.means[3 * 2 + 1] = std::numeric_limits<float>::quiet_NaN();
  m.log_scales[3 * 7] = std::numeric_limits<float>::infinity();
  m.opacity_logits[7] = -std::numeric_limits<float>::infinity();
  write_gaussian_ply(dir / "m.ply", m);
  expect_ply_rejected(dir / "m.ply",
                      "2 of 10 Gaussians have NaN or infinite parameters (the first: "
                      "vertex 2)");
}

TEST(Ply, MalformedFilesAreRejected) {
  TempDir dir;
  const std::string good_props =
      "property float x\nproperty float y\nproperty float z\nproperty float f_dc_0\n"
      "property float f_dc_1\nproperty float f_dc_2\nproperty float opacity\n"
      "property float scale_0\nproperty float scale_1\nproperty float scale_2\n"
      "property float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\n";
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"magic.ply", "plx\n", "not a PLY"},
      {"be.ply", "ply\nformat binary_big_endian 1.0\nelement vertex 0\nend_header\n", "big-endian"},
      {"type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n",
       "unknown property type"},
      {"missing.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n",
       "'y' is missing"},
      {"list.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\n" + good_props +
           "property list uchar int idx\nend_header\n",
       "is a list"},
      {"rest.ply",
       "ply\nformat ascii 1.0\nelement vertex 0\n" + good_props +
           "property float f_rest_0\nend_header\n",
       "SH degree"},
      {"nan.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\n" + good_props +
           "end_header\n0 0 zero 0 0 0 0 0 0 0 1 0 0 0\n",
       "not a number"},
      // A float label must be a whole int32: its cast would be undefined.
      {"biglabel.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\n" + good_props +
           "property float label\nend_header\n0 0 0 0 0 0 0 0 0 0 1 0 0 0 1e20\n",
       "vertex 0: label 1e+20 is not an integer object ID"},
      {"nanlabel.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\n" + good_props +
           "property float label\nend_header\n0 0 0 0 0 0 0 0 0 0 1 0 0 0 nan\n",
       "is not an integer object ID"},
      {"halflabel.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\n" + good_props +
           "property float label\nend_header\n0 0 0 0 0 0 0 0 0 0 1 0 0 0 2.5\n",
       "label 2.5 is not"},
      {"short.ply",
       "ply\nformat ascii 1.0\nelement vertex 2\n" + good_props +
           "end_header\n0 0 0 0 0 0 0 0 0 0 1 0 0 0\n",
       "truncated"},
      {"novertex.ply", "ply\nformat ascii 1.0\nelement face 0\nend_header\n", "no 'vertex'"},
      // Counts that lie about the rows before the vertex element: refused at
      // the end of the file, not skipped one empty row at a time.
      {"asciiface.ply",
       "ply\nformat ascii 1.0\nelement face 99999999999999\nproperty int a\nelement vertex 1\n" +
           good_props + "end_header\n0\n",
       "truncated in element 'face'"},
      {"binaryface.ply",
       "ply\nformat binary_little_endian 1.0\nelement face 4611686018427387904\n"
       "property int a\nelement vertex 1\n" +
           good_props + "end_header\n0123",
       "truncated in element 'face'"},
  };
  for (const auto& [name, text, why] : cases) {
    write_file(dir / name, text);
    SCOPED_TRACE(name);
    expect_ply_rejected(dir / name, why);
  }
  expect_ply_rejected(dir / "does_not_exist.ply", "cannot open");
}

// A point cloud with a list among its vertex properties cannot be read row by
// row; its vertex count must not be allocated before that is found out.
TEST(Ply, PointCloudWithAVertexListIsRejectedBeforeAllocating) {
  TempDir dir;
  write_file(dir / "p.ply",
             "ply\nformat binary_little_endian 1.0\nelement vertex 2305843009213693951\n"
             "property float x\nproperty float y\nproperty float z\n"
             "property list uchar int idx\nend_header\n");
  expect_ply_rejected(dir / "p.ply", "'idx' is a list", read_point_ply);
}

TEST(Ply, FailedWriteLeavesNoFile) {
  TempDir dir;
  std::filesystem::create_directories(dir / "m.ply");  // a folder in the way
  EXPECT_ANY_THROW(write_gaussian_ply(dir / "m.ply", random_model(2, false)));
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(e.path().filename(), "m.ply") << "left behind: " << e.path();
}

}  // namespace
}  // namespace splat
