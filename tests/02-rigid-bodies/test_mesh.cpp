// Chapter 2: triangle meshes — the strict OBJ reader and writer, the topology checks, the mesh
// generators and rigid images of meshes (core code, no exercise).
//
// Independent references: the OBJ files of tests/02-rigid-bodies/data, whose expected vertices,
// faces, lines and offending edges are worked out by hand in their comments; the signed volume
// (1/6) Σ a·(b × c) of the divergence theorem, summed here with no library code; Euler's formula
// V − E + F = 2 − 2g (sphere g = 0, torus g = 1); the implicit equations of sphere, torus and
// cylinder.
//
// Tolerances: a generated vertex is a few floating-point operations on numbers of order 1, so
// geometric identities hold to 1e-14 relative unless a comment says otherwise; the reader and the
// writer must be exact (==).

#include <gtest/gtest.h>

#include <Eigen/Geometry>  // cross()
#include <Eigen/LU>        // determinant()
#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <sys/stat.h>  // mkfifo

#include "grbd/body/triangle_mesh.hpp"
#include "grbd/core/error.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/temp_dir.hpp"
#include "grbd_test/worst_case.hpp"

namespace {

namespace fs = std::filesystem;
using grbd::Matrix3;
using grbd::Vector3;
using grbd::body::analyse_topology;
using grbd::body::Faces;
using grbd::body::MeshError;
using grbd::body::MeshTopology;
using grbd::body::read_obj;
using grbd::body::require_closed_oriented;
using grbd::body::TriangleMesh;
using grbd::body::write_obj;
using grbd::test::describe;
using grbd::test::TempDir;
using grbd::test::WorstCase;

constexpr double pi = std::numbers::pi;

fs::path data_file(const char* name) { return fs::path(GRBD_TEST_DATA_DIR) / name; }

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The message of the MeshError that `read` throws, or a failure if it throws none.
template <class F>
std::string mesh_error_message(F&& read) {
  try {
    read();
  } catch (const MeshError& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected a grbd::body::MeshError, none was thrown";
  return {};
}

/// The message with which require_closed_oriented() rejects the mesh read from `file`; it must
/// start with the file's name.
std::string rejection_message(const TriangleMesh& mesh, const fs::path& file) {
  const std::string message =
      mesh_error_message([&] { require_closed_oriented(mesh, file.string()); });
  EXPECT_EQ(message.rfind(file.string() + ": ", 0), 0U) << message;
  return message;
}

/// Reference: the divergence theorem with the field x/3, V = (1/6) Σ_faces a·(b × c).
double signed_volume(const TriangleMesh& mesh) {
  double six_volume = 0.0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Vector3 a = mesh.V.row(mesh.F(f, 0)).transpose();
    const Vector3 b = mesh.V.row(mesh.F(f, 1)).transpose();
    const Vector3 c = mesh.V.row(mesh.F(f, 2)).transpose();
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

/// The number of distinct undirected edges.
std::size_t edge_count(const TriangleMesh& mesh) {
  std::set<std::pair<int, int>> edges;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int i = mesh.F(f, k);
      const int j = mesh.F(f, (k + 1) % 3);
      edges.insert({std::min(i, j), std::max(i, j)});
    }
  }
  return edges.size();
}

/// Euler characteristic V − E + F.
long euler_characteristic(const TriangleMesh& mesh) {
  return static_cast<long>(mesh.V.rows()) - static_cast<long>(edge_count(mesh)) +
         static_cast<long>(mesh.F.rows());
}

Vector3 face_normal(const TriangleMesh& mesh, Eigen::Index f) {
  const Vector3 a = mesh.V.row(mesh.F(f, 0)).transpose();
  const Vector3 b = mesh.V.row(mesh.F(f, 1)).transpose();
  const Vector3 c = mesh.V.row(mesh.F(f, 2)).transpose();
  return (b - a).cross(c - a);
}

Vector3 face_centroid(const TriangleMesh& mesh, Eigen::Index f) {
  return (mesh.V.row(mesh.F(f, 0)) + mesh.V.row(mesh.F(f, 1)) + mesh.V.row(mesh.F(f, 2)))
             .transpose() /
         3.0;
}

/// The unit corner tetrahedron as the data files write it.
Faces corner_tetrahedron_faces() {
  Faces F(4, 3);
  F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  return F;
}

grbd::body::Vertices corner_tetrahedron_vertices() {
  grbd::body::Vertices V(4, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  return V;
}

}  // namespace

// ----------------------------------------------------------------------------------------------
// read_obj
// ----------------------------------------------------------------------------------------------

// Reference: the file's own content (every vertex-reference form, the ignored statements, tabs,
// an exponent, a leading '+', a weight w and a trailing comment), read by hand. Exact.
TEST(ObjReader, ReadsEveryVertexReferenceForm) {
  const TriangleMesh mesh = read_obj(data_file("tetrahedron_forms.obj"));
  EXPECT_EQ(mesh.V, corner_tetrahedron_vertices());
  EXPECT_EQ(mesh.F, corner_tetrahedron_faces());
}

// Reference: −k is the k-th latest vertex read, worked out in the file's comment. Exact.
TEST(ObjReader, ResolvesNegativeIndicesRelativeToTheLatestVertex) {
  const TriangleMesh mesh = read_obj(data_file("negative_indices.obj"));
  EXPECT_EQ(mesh.V, corner_tetrahedron_vertices());
  EXPECT_EQ(mesh.F, corner_tetrahedron_faces());
}

// Reference: the fan rule (a, b, c, d) → (a, b, c), (a, c, d), applied by hand to the six quads
// of the unit cube; the fan keeps the orientation, so the result is closed with volume 1.
TEST(ObjReader, SplitsQuadsIntoOrientedFans) {
  const TriangleMesh mesh = read_obj(data_file("cube_quads.obj"));
  Faces expected(12, 3);
  expected << 0, 3, 2, 0, 2, 1,  //
      4, 5, 6, 4, 6, 7,          //
      0, 1, 5, 0, 5, 4,          //
      3, 7, 6, 3, 6, 2,          //
      0, 4, 7, 0, 7, 3,          //
      1, 2, 6, 1, 6, 5;
  EXPECT_EQ(mesh.V.rows(), 8);
  EXPECT_EQ(mesh.F, expected);
  EXPECT_TRUE(analyse_topology(mesh).closed_oriented_manifold());
  EXPECT_EQ(signed_volume(mesh), 1.0);  // sums of products of 0 and 1: exact
}

// Reference: the fan rule on a pentagon v1 … v5: (0,1,2), (0,2,3), (0,3,4).
TEST(ObjReader, SplitsLargerPolygonsIntoFans) {
  const TempDir dir;
  const TriangleMesh mesh =
      read_obj(dir.write("pentagon.obj",
                         "v 1 0 0\nv 0.3 0.9 0\nv -0.8 0.6 0\nv -0.8 -0.6 0\nv 0.3 -0.9 0\n"
                         "f 1 2 3 4 5\n"));
  Faces expected(3, 3);
  expected << 0, 1, 2, 0, 2, 3, 0, 3, 4;
  EXPECT_EQ(mesh.F, expected);
}

// Reference: the same tetrahedron as tetrahedron_forms.obj, with a UTF-8 byte order mark and
// Windows line ends (CR LF), and no line end after the last line.
TEST(ObjReader, AcceptsWindowsLineEndsAndByteOrderMark) {
  const TempDir dir;
  const TriangleMesh mesh =
      read_obj(dir.write("windows.obj",
                         "\xEF\xBB\xBFv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nv 0 0 1\r\n\r\n"
                         "f 1 3 2\r\nf 1 2 4\r\nf 1 4 3\r\nf 2 3 4"));
  EXPECT_EQ(mesh.V, corner_tetrahedron_vertices());
  EXPECT_EQ(mesh.F, corner_tetrahedron_faces());
}

// Reference: the line numbers and offending tokens stated in the data files' comments. The
// message must be "<file>:<line>: expected ..., found '<token>'".
TEST(ObjReader, RejectsMalformedDataFilesNamingFileLineAndToken) {
  struct Case {
    const char* file;
    int line;
    const char* expected;
    const char* found;
  };
  const std::array<Case, 5> cases = {{
      {"bad_number.obj", 3, "a finite decimal number", "'1,5'"},
      {"index_out_of_range.obj", 9, "a vertex index in [1, 4] or [-4, -1]", "'5'"},
      {"unknown_statement.obj", 5, "a statement", "'l'"},
      {"short_face.obj", 5, "a face of at least three vertices", "'f 1 2'"},
      {"no_faces.obj", 4, "at least one face", "end of file after 3 vertices"},
  }};
  for (const Case& c : cases) {
    const fs::path file = data_file(c.file);
    const std::string message = mesh_error_message([&] { read_obj(file); });
    EXPECT_EQ(message.rfind(file.string() + ":" + std::to_string(c.line) + ": expected ", 0), 0U)
        << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << message;
    EXPECT_NE(message.find(std::string("found ") + c.found), std::string::npos) << message;
  }
}

// Reference: the grammar of triangle_mesh.hpp: each line below breaks exactly one rule, on the
// line given, and the message quotes the offending token.
TEST(ObjReader, RejectsEveryBrokenRuleWithLineAndToken) {
  struct Case {
    std::string content;
    int line;
    std::string found;
  };
  const std::string tetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";  // lines 1–4
  const std::vector<Case> cases = {
      {tetra + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 0\n", 8, "'0'"},  // index 0 does not exist
      {tetra + "f 1 3 -5\n", 5, "'-5'"},                           // before the first vertex
      {"v 0 0 0\nf 1 2 3\nv 1 0 0\nv 0 1 0\n", 2, "'2'"},          // not read yet
      {tetra + "f 1 3 2.0\n", 5, "'2.0'"},                         // not an integer
      {tetra + "f 1 3 +2\n", 5, "'+2'"},                           // no sign on indices
      {tetra + "f 1 3 99999999999\n", 5, "'99999999999'"},         // overflows int
      {tetra + "f 1/ 3 2\n", 5, "'1/'"},                           // empty texture index
      {tetra + "f 1// 3 2\n", 5, "'1//'"},                         // empty normal index
      {tetra + "f 1/2/3/4 3 2\n", 5, "'1/2/3/4'"},                 // too many slashes
      {tetra + "f 1/0/1 3 2\n", 5, "'1/0/1'"},                     // zero texture index
      {tetra + "f /1 3 2\n", 5, "'/1'"},                           // no vertex index
      {tetra + "f\n", 5, "'f'"},                                   // no vertices
      {"v 0 0 0\nv 1 nan 0\n", 2, "'nan'"},                        // not finite
      {"v 0 0 0\nv 1 inf 0\n", 2, "'inf'"},                        // not finite
      {"v 0 0 0\nv 1 1e999 0\n", 2, "'1e999'"},                    // overflows double
      {"v 0 0 0\nv 1 0x10 0\n", 2, "'0x10'"},                      // not decimal
      {"v 0 0 0\nv 1 2 3 4 5\n", 2, "'5'"},                        // too many numbers
      {"v 0 0 0\nv 1 2 3 w\n", 2, "'w'"},                          // weight not a number
      {"v 1 2\n", 1, "'v 1 2'"},                                   // too few numbers
      {"v 0 0 0\n\t v 1 2 \t# two\n", 2, "'v 1 2'"},               // quoted without blanks
      {"v 0 0 0\n\n  V 1 0 0\n", 3, "'V'"},                        // keywords are lower case
      {"v 0 0 0\nv 1 0 0 \\\n 0\n", 2, "'\\'"},                    // no line continuation
      {"v 0 0 0\nv 1 0\x01 0\n", 2, "'0\\x01'"},                   // control character
      // Binary bytes (or any keyword that is not a short word) are not quoted: a file that is
      // not OBJ has nothing of its text repeated in the message.
      {"v 0 0 0\n\xff\xfe v\n", 2, "a line that is not OBJ (the file is not an OBJ file)"},
      {std::string("v 0 0 0\nv 0\0 0 0\n", 17), 2, "'0\\x00'"},    // a NUL byte
  };
  const TempDir dir;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const fs::path file = dir.write("case" + std::to_string(k) + ".obj", cases[k].content);
    const std::string message = mesh_error_message([&] { read_obj(file); });
    EXPECT_EQ(message.rfind(file.string() + ":" + std::to_string(cases[k].line) + ": expected ", 0),
              0U)
        << "case " << k << ": " << message;
    EXPECT_NE(message.find("found " + cases[k].found), std::string::npos)
        << "case " << k << ": " << message;
  }
}

// Reference: the contract "names the file": a missing file and a directory are MeshErrors whose
// message starts with the path.
TEST(ObjReader, NamesAMissingOrUnreadableFile) {
  const TempDir dir;
  const fs::path missing = dir.path() / "no_such_mesh.obj";
  const std::string message = mesh_error_message([&] { read_obj(missing); });
  EXPECT_EQ(message.rfind(missing.string() + ": ", 0), 0U) << message;
  EXPECT_NE(message.find("no such file"), std::string::npos) << message;
  const std::string directory = mesh_error_message([&] { read_obj(dir.path()); });
  EXPECT_EQ(directory.rfind(dir.path().string() + ": ", 0), 0U) << directory;
  EXPECT_NE(directory.find("directory"), std::string::npos) << directory;
  // A device that never ends must be refused, not read until memory runs out.
  if (fs::exists("/dev/zero")) {
    const std::string device = mesh_error_message([&] { read_obj("/dev/zero"); });
    EXPECT_NE(device.find("not a regular file"), std::string::npos) << device;
  }
}

// Reference: issue 11 (fuzzing): a path that exists but cannot be examined (a loop of symbolic
// links, a name component longer than NAME_MAX) was reported as "no such file". The message must
// give the operating system's reason instead, and "no such file" only for a missing file.
TEST(ObjReader, DistinguishesAMissingFileFromOneThatCannotBeExamined) {
  const TempDir dir;
  const fs::path loop = dir.path() / "loop.obj";
  fs::create_symlink(dir.path() / "loop_back.obj", loop);
  fs::create_symlink(loop, dir.path() / "loop_back.obj");
  std::string message = mesh_error_message([&] { read_obj(loop); });
  EXPECT_EQ(message.rfind(loop.string() + ": ", 0), 0U) << message;
  EXPECT_EQ(message.find("no such file"), std::string::npos) << message;
  EXPECT_NE(message.find(std::make_error_code(std::errc::too_many_symbolic_link_levels).message()),
            std::string::npos)
      << message;

  const fs::path long_name = dir.path() / std::string(300, 'x');  // NAME_MAX is 255 on Linux
  message = mesh_error_message([&] { read_obj(long_name); });
  EXPECT_EQ(message.find("no such file"), std::string::npos) << message;
  EXPECT_NE(message.find(std::make_error_code(std::errc::filename_too_long).message()),
            std::string::npos)
      << message;

  // A missing file below an existing one: the path names no file, and says why.
  const fs::path file = dir.write("mesh.obj", "");
  message = mesh_error_message([&] { read_obj(file / "inside.obj"); });
  EXPECT_NE(message.find("no such file"), std::string::npos) << message;
}

// Reference: issue 11 (fuzzing): a regular file that exists but cannot be opened was reported
// without the reason. As root, permissions do not stop a read, so a file of /proc that refuses to
// be opened for reading stands in (/proc/sys/vm/drop_caches is write-only even for root); the
// expected reason is what fopen itself reports for the same file.
TEST(ObjReader, GivesTheReasonAFileCannotBeOpened) {
  const TempDir dir;
  fs::path file = dir.write("locked.obj", "v 0 0 0\n");
  fs::permissions(file, fs::perms::none);
  std::FILE* probe = std::fopen(file.c_str(), "rb");
  if (probe != nullptr) {  // root: try the write-only kernel file
    std::fclose(probe);
    file = "/proc/sys/vm/drop_caches";
    probe = fs::is_regular_file(file) ? std::fopen(file.c_str(), "rb") : nullptr;
    if (probe != nullptr || !fs::is_regular_file(file)) {
      if (probe != nullptr) std::fclose(probe);
      GTEST_SKIP() << "no regular file here that cannot be opened for reading";
    }
  }
  const std::string reason = std::generic_category().message(errno);
  const std::string message = mesh_error_message([&] { read_obj(file); });
  EXPECT_EQ(message.rfind(file.string() + ": cannot open the OBJ file", 0), 0U) << message;
  EXPECT_NE(message.find(reason), std::string::npos) << message;
}

// Reference: issue 11 (fuzzing): a read error (here /proc/self/mem, which opens but fails to read
// at offset 0 with EIO) escaped read_obj as std::ios_base::failure, without the file name. It
// must be a MeshError naming the file and the reason.
TEST(ObjReader, ReportsAReadErrorAsAMeshErrorNamingTheFile) {
  const fs::path file = "/proc/self/mem";
  if (!fs::is_regular_file(file)) GTEST_SKIP() << file << " is not available";
  std::string message;
  try {
    read_obj(file);
    ADD_FAILURE() << "reading " << file << " should fail";
  } catch (const MeshError& error) {
    message = error.what();
  } catch (const std::exception& error) {
    ADD_FAILURE() << "expected a grbd::body::MeshError, got: " << error.what();
  }
  EXPECT_EQ(message.rfind(file.string() + ": cannot read the OBJ file: read error", 0), 0U)
      << message;
  EXPECT_NE(message.find(std::make_error_code(std::errc::io_error).message()), std::string::npos)
      << message;
}

// Reference: issue 11 (fuzzing): opening a FIFO for reading blocks until a writer comes, so a
// FIFO must be refused from its type without being opened (this test would hang otherwise).
TEST(ObjReader, RefusesAFifoWithoutOpeningIt) {
  const TempDir dir;
  const fs::path fifo = dir.path() / "pipe.obj";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::generic_category().message(errno);
  const std::string message = mesh_error_message([&] { read_obj(fifo); });
  EXPECT_EQ(message.rfind(fifo.string() + ": ", 0), 0U) << message;
  EXPECT_NE(message.find("not a regular file"), std::string::npos) << message;
  EXPECT_NE(message.find("FIFO"), std::string::npos) << message;
}

// Reference: issue 11 (fuzzing) and IEEE 754 rounding: 1e-400 lies below half the smallest
// subnormal double, so its correctly rounded value is ±0 (what strtod returns too); it was
// refused as "not a finite decimal number". A coordinate that underflows is read as ±0. A
// number that overflows is refused as such, with the largest double in the message.
TEST(ObjReader, ReadsUnderflowingCoordinatesAsZeroAndNamesOverflow) {
  const TempDir dir;
  const std::string faces = "f 1 2 3\n";
  const fs::path tiny = dir.write(
      "tiny.obj",
      "v 1e-400 -1e-400 0.0000000001e-390\nv 1 0 2e-324\nv 0 1 -1e-99999999999\n" + faces);
  const TriangleMesh mesh = read_obj(tiny);
  ASSERT_EQ(mesh.V.rows(), 3);
  EXPECT_EQ(mesh.V(0, 0), 0.0);
  EXPECT_FALSE(std::signbit(mesh.V(0, 0)));
  EXPECT_EQ(mesh.V(0, 1), 0.0);
  EXPECT_TRUE(std::signbit(mesh.V(0, 1)));  // −1e-400 rounds to −0
  EXPECT_EQ(mesh.V(0, 2), 0.0);
  EXPECT_EQ(mesh.V(1, 2), 0.0);
  EXPECT_EQ(mesh.V(2, 2), 0.0);
  EXPECT_TRUE(std::signbit(mesh.V(2, 2)));

  for (const std::string huge : {"1e999", "-1e309", "123456789e99999999999999", "0.1e310"}) {
    const fs::path file = dir.write("huge.obj", "v 0 0 0\nv 1 " + huge + " 0\n" + faces);
    const std::string message = mesh_error_message([&] { read_obj(file); });
    EXPECT_EQ(message.rfind(file.string() + ":2: expected ", 0), 0U) << message;
    EXPECT_NE(message.find("found '" + huge + "', which overflows"), std::string::npos) << message;
    EXPECT_NE(message.find("1.7976931348623157e+308"), std::string::npos) << message;
  }
}

// Reference: issue 11 (fuzzing): a face index beyond the range of int (2147483648 = 2³¹) is an
// integer out of range and must get the range message, not the generic form message.
TEST(ObjReader, CallsAFaceIndexBeyondTheIntRangeOutOfRange) {
  const TempDir dir;
  const std::string tetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
  for (const std::string index :
       {"2147483648", "-2147483649", "4294967297", "99999999999999999999999", "2147483648/1"}) {
    const fs::path file = dir.write("big_index.obj", tetra + "f 1 2 " + index + "\n");
    const std::string message = mesh_error_message([&] { read_obj(file); });
    EXPECT_EQ(message, file.string() + ":5: expected a vertex index in [1, 4] or [-4, -1], " +
                           "found '" + index + "'");
  }
  // Texture and normal indices are checked as non-zero integers but not used: a large one is
  // an integer all the same.
  const fs::path file = dir.write("big_texture.obj", tetra + "f 1/4294967297 3 2\n");
  EXPECT_EQ(read_obj(file).F.rows(), 1);
}

// Reference: issue 11 (fuzzing): the vertices (±1e308, ±1e308, ±1e308) form a regular
// tetrahedron whose signed volume a·(b × c)/6 ≈ 1e924 overflows; it was reported as "expected
// outward-oriented faces … signed volume -nan". The overflow must be named as such, with the
// file and the largest coordinate magnitude.
TEST(MeshTopology, NamesCoordinatesSoLargeThatTheVolumeOverflows) {
  const TempDir dir;
  const fs::path file = dir.write("huge.obj",
                                  "v 1e308 1e308 1e308\nv -1e308 -1e308 1e308\n"
                                  "v 1e308 -1e308 -1e308\nv -1e308 1e308 -1e308\n"
                                  "f 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n");
  const TriangleMesh mesh = read_obj(file);
  const std::string message = rejection_message(mesh, file);
  EXPECT_NE(message.find("coordinates too large"), std::string::npos) << message;
  EXPECT_NE(message.find("overflow"), std::string::npos) << message;
  EXPECT_NE(message.find("1e+308"), std::string::npos) << message;
  EXPECT_EQ(message.find("nan"), std::string::npos) << message;
  EXPECT_EQ(message.find("outward"), std::string::npos) << message;

  // Scaled down to 1e100 the volume (≈ 1e300) is finite and the mesh passes.
  TriangleMesh scaled = mesh;
  scaled.V *= 1e-208;
  EXPECT_NO_THROW(require_closed_oriented(scaled, "scaled"));
}

// Reference: the contract of read_obj on any input: it returns a mesh whose face indices are in
// [0, #V), or throws MeshError; nothing else, no crash, no hang. Inputs: seeded random bytes, and
// seeded one-byte mutations of a valid file (biased towards the characters of OBJ so that many
// mutants are nearly valid).
TEST(ObjReader, NeverCrashesOnGarbage) {
  const TempDir dir;
  std::mt19937_64 engine(2001);
  const std::string valid = read_text(data_file("tetrahedron_forms.obj"));
  ASSERT_FALSE(valid.empty());
  constexpr char kAlphabet[] = " \t\n\r/#-+.0123456789efvnt\0\xff";
  const std::string alphabet(kAlphabet, sizeof kAlphabet - 1);  // the NUL included
  int accepted = 0;
  int rejected = 0;
  auto check = [&](const std::string& content, int k) {
    const fs::path file = dir.write("garbage.obj", content);
    try {
      const TriangleMesh mesh = read_obj(file);
      ++accepted;
      ASSERT_GT(mesh.F.rows(), 0) << "input " << k;
      ASSERT_GE(mesh.F.minCoeff(), 0) << "input " << k;
      ASSERT_LT(mesh.F.maxCoeff(), mesh.V.rows()) << "input " << k;
      ASSERT_TRUE(mesh.V.allFinite()) << "input " << k;
    } catch (const MeshError&) {
      ++rejected;
    }
  };
  std::uniform_int_distribution<int> byte(0, 255);
  for (int k = 0; k < 100; ++k) {
    std::string content(std::uniform_int_distribution<std::size_t>(0, 2000)(engine), '\0');
    for (char& c : content) c = static_cast<char>(byte(engine));
    check(content, k);
  }
  for (int k = 0; k < 500; ++k) {
    std::string content = valid;
    const std::size_t at =
        std::uniform_int_distribution<std::size_t>(0, content.size() - 1)(engine);
    const char c =
        alphabet[std::uniform_int_distribution<std::size_t>(0, alphabet.size() - 1)(engine)];
    switch (k % 3) {
      case 0:
        content[at] = c;
        break;
      case 1:
        content.insert(at, 1, c);
        break;
      default:
        content.erase(at, 1);
        break;
    }
    check(content, 100 + k);
  }
  EXPECT_EQ(accepted + rejected, 600);
  EXPECT_GE(rejected, 100);  // every random-bytes input at least
  EXPECT_GT(accepted, 0);    // e.g. mutations inside comments
}

// ----------------------------------------------------------------------------------------------
// write_obj
// ----------------------------------------------------------------------------------------------

// Reference: 17 significant digits identify every double (IEEE 754, §5.12.2), so write → read
// must give back the same bits: compared with ==, for a rotated and shifted icosphere and for
// numbers from subnormal to near overflow.
TEST(ObjWriter, RoundTripIsExact) {
  const TempDir dir;
  grbd::test::Random rng(2002);
  const Matrix3 A = rng.rotation();
  const TriangleMesh sphere =
      grbd::body::transformed(grbd::body::icosphere_mesh(1.2345, 2), A, rng.vector3(-10, 10));
  const fs::path file = dir.write("sphere.obj", "");
  write_obj(sphere, file, "an icosphere");
  const TriangleMesh back = read_obj(file);
  EXPECT_EQ(back.V, sphere.V);
  EXPECT_EQ(back.F, sphere.F);

  TriangleMesh extreme;
  extreme.V.resize(6, 3);
  extreme.V << 5e-324, -2.2250738585072014e-308, 1.7976931348623157e308,    //
      -0.0, 0.1, 1.0 / 3.0,                                                 //
      1e-300, -1e300, 123456789.123456789,                                  //
      rng.uniform(), rng.uniform(-1e10, 1e10), rng.uniform(-1e-10, 1e-10),  //
      pi, std::numbers::e, -std::numbers::sqrt2,                            //
      4.9406564584124654e-320, 2.0, -3.0;
  extreme.F.resize(2, 3);
  extreme.F << 0, 1, 2, 3, 4, 5;
  write_obj(extreme, dir.path() / "extreme.obj");
  const TriangleMesh extreme_back = read_obj(dir.path() / "extreme.obj");
  EXPECT_EQ(extreme_back.V, extreme.V);
  EXPECT_EQ(extreme_back.F, extreme.F);
  EXPECT_TRUE(std::signbit(extreme_back.V(1, 0)));  // −0 stays −0
}

// Reference: the OBJ format: comment lines start with '#', one per line of the comment, then the
// 'v' lines and the 1-based 'f' lines.
TEST(ObjWriter, WritesCommentVertexAndFaceLines) {
  const TempDir dir;
  TriangleMesh mesh;
  mesh.V = corner_tetrahedron_vertices();
  mesh.F = corner_tetrahedron_faces();
  const fs::path file = dir.path() / "tetrahedron.obj";
  write_obj(mesh, file, "unit corner tetrahedron\nwritten by a test");
  EXPECT_EQ(read_text(file),
            "# unit corner tetrahedron\n# written by a test\n"
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
            "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
}

// Reference: the contract: a file that cannot be written, or a mesh that read_obj would refuse
// (no faces, a non-finite coordinate, an index out of range), is a MeshError naming the file.
TEST(ObjWriter, RefusesUnwritableFilesAndMeshesThatCannotBeReadBack) {
  const TempDir dir;
  TriangleMesh mesh;
  mesh.V = corner_tetrahedron_vertices();
  mesh.F = corner_tetrahedron_faces();
  const fs::path unwritable = dir.path() / "no_such_directory" / "mesh.obj";
  const std::string message = mesh_error_message([&] { write_obj(mesh, unwritable); });
  EXPECT_EQ(message.rfind(unwritable.string() + ": ", 0), 0U) << message;

  const fs::path file = dir.path() / "bad.obj";
  TriangleMesh no_faces = mesh;
  no_faces.F.resize(0, 3);
  TriangleMesh not_finite = mesh;
  not_finite.V(2, 1) = std::nan("");
  TriangleMesh out_of_range = mesh;
  out_of_range.F(3, 2) = 4;
  for (const TriangleMesh* bad : {&no_faces, &not_finite, &out_of_range}) {
    const std::string refused = mesh_error_message([&] { write_obj(*bad, file); });
    EXPECT_EQ(refused.rfind(file.string() + ": ", 0), 0U) << refused;
  }
}

// ----------------------------------------------------------------------------------------------
// analyse_topology and require_closed_oriented
// ----------------------------------------------------------------------------------------------

// Reference: open_box.obj is the unit cube without its top: the four top edges are boundary
// edges, the first of them (4, 5), used by face 3 only (worked out in the file's comment).
TEST(MeshTopology, CountsTheBoundaryEdgesOfAnOpenBox) {
  const fs::path file = data_file("open_box.obj");
  const TriangleMesh mesh = read_obj(file);
  const MeshTopology t = analyse_topology(mesh);
  EXPECT_EQ(t.boundary_edges, 4U);
  EXPECT_EQ(t.non_manifold_edges, 0U);
  EXPECT_EQ(t.inconsistent_edges, 0U);
  EXPECT_EQ(t.degenerate_faces, 0U);
  EXPECT_EQ(t.invalid_indices, 0U);
  EXPECT_FALSE(t.closed_oriented_manifold());
  const std::string message = rejection_message(mesh, file);
  EXPECT_NE(message.find("4 boundary edges"), std::string::npos) << message;
  EXPECT_NE(message.find("boundary edge (4, 5) of face 3"), std::string::npos) << message;
}

// Reference: inconsistent_tetrahedron.obj has one face turned inward, so its three edges are
// each run in the same direction by two faces; the first, (1, 2), from 2 to 1 by faces 0 and 3.
TEST(MeshTopology, CountsInconsistentlyOrientedEdges) {
  const fs::path file = data_file("inconsistent_tetrahedron.obj");
  const TriangleMesh mesh = read_obj(file);
  const MeshTopology t = analyse_topology(mesh);
  EXPECT_EQ(t.inconsistent_edges, 3U);
  EXPECT_EQ(t.boundary_edges + t.non_manifold_edges + t.degenerate_faces + t.invalid_indices, 0U);
  const std::string message = rejection_message(mesh, file);
  EXPECT_NE(message.find("3 inconsistently oriented edges"), std::string::npos) << message;
  EXPECT_NE(message.find("edge (1, 2): faces 0 and 3 both traverse it from 2 to 1"),
            std::string::npos)
      << message;
}

// Reference: non_manifold_fin.obj adds a fin on edge (0, 1): three faces there, and the fin's
// two other edges are boundary edges.
TEST(MeshTopology, CountsNonManifoldEdges) {
  const fs::path file = data_file("non_manifold_fin.obj");
  const TriangleMesh mesh = read_obj(file);
  const MeshTopology t = analyse_topology(mesh);
  EXPECT_EQ(t.non_manifold_edges, 1U);
  EXPECT_EQ(t.boundary_edges, 2U);
  EXPECT_EQ(t.inconsistent_edges + t.degenerate_faces + t.invalid_indices, 0U);
  const std::string message = rejection_message(mesh, file);
  EXPECT_NE(message.find("1 non-manifold edges"), std::string::npos) << message;
  EXPECT_NE(message.find("non-manifold edge (0, 1) shared by 3 faces"), std::string::npos)
      << message;
}

// Reference: inward_tetrahedron.obj is closed and consistently oriented, with signed volume
// −1/6: only the volume check can reject it.
TEST(MeshTopology, RejectsAnInwardOrientedSurface) {
  const fs::path file = data_file("inward_tetrahedron.obj");
  const TriangleMesh mesh = read_obj(file);
  EXPECT_TRUE(analyse_topology(mesh).closed_oriented_manifold());
  EXPECT_DOUBLE_EQ(signed_volume(mesh), -1.0 / 6.0);
  const std::string message = rejection_message(mesh, file);
  EXPECT_NE(message.find("-0.1666666666666666"), std::string::npos) << message;
  EXPECT_NE(message.find("inward"), std::string::npos) << message;
}

// Reference: the definitions of MeshTopology, on meshes built here: a repeated vertex index, an
// exactly zero area, indices outside [0, #V) (each bad index counted), and the two-sided
// "pillow", which is closed and consistently oriented but encloses no volume.
TEST(MeshTopology, CountsDegenerateFacesInvalidIndicesAndRejectsZeroVolume) {
  TriangleMesh tetra;
  tetra.V = corner_tetrahedron_vertices();
  tetra.F = corner_tetrahedron_faces();
  ASSERT_TRUE(analyse_topology(tetra).closed_oriented_manifold());
  EXPECT_NO_THROW(require_closed_oriented(tetra, "tetra"));

  TriangleMesh repeated = tetra;
  repeated.F.conservativeResize(5, 3);
  repeated.F.row(4) << 2, 2, 3;
  MeshTopology t = analyse_topology(repeated);
  EXPECT_EQ(t.degenerate_faces, 1U);
  EXPECT_EQ(t.boundary_edges + t.non_manifold_edges + t.inconsistent_edges, 0U);
  std::string message = mesh_error_message([&] { require_closed_oriented(repeated, "rep"); });
  EXPECT_NE(message.find("1 degenerate faces"), std::string::npos) << message;
  EXPECT_NE(message.find("degenerate face 4 (2, 2, 3)"), std::string::npos) << message;

  TriangleMesh collinear = tetra;  // vertex 4 = (2, 0, 0) on the line through 0 and 1
  collinear.V.conservativeResize(5, 3);
  collinear.V.row(4) << 2.0, 0.0, 0.0;
  collinear.F.conservativeResize(5, 3);
  collinear.F.row(4) << 0, 1, 4;
  t = analyse_topology(collinear);
  EXPECT_EQ(t.degenerate_faces, 1U);
  EXPECT_EQ(t.non_manifold_edges, 1U);  // (0, 1) now has three faces
  EXPECT_EQ(t.boundary_edges, 2U);

  TriangleMesh invalid = tetra;
  invalid.F(1, 2) = 4;
  invalid.F(2, 0) = -1;
  t = analyse_topology(invalid);
  EXPECT_EQ(t.invalid_indices, 2U);
  message = mesh_error_message([&] { require_closed_oriented(invalid, "bad indices"); });
  EXPECT_EQ(message.rfind("bad indices: ", 0), 0U) << message;
  EXPECT_NE(message.find("2 invalid vertex indices"), std::string::npos) << message;
  EXPECT_NE(message.find("face 1 (0, 1, 4) has a vertex index outside [0, 4)"), std::string::npos)
      << message;

  TriangleMesh pillow;
  pillow.V = corner_tetrahedron_vertices().topRows(3);
  pillow.F.resize(2, 3);
  pillow.F << 0, 1, 2, 0, 2, 1;
  EXPECT_TRUE(analyse_topology(pillow).closed_oriented_manifold());
  message = mesh_error_message([&] { require_closed_oriented(pillow, "pillow"); });
  EXPECT_NE(message.find("positive volume"), std::string::npos) << message;

  TriangleMesh empty;
  message = mesh_error_message([&] { require_closed_oriented(empty, "empty"); });
  EXPECT_NE(message.find("found no faces"), std::string::npos) << message;

  TriangleMesh not_finite = tetra;
  not_finite.V(3, 2) = std::numeric_limits<double>::infinity();
  message = mesh_error_message([&] { require_closed_oriented(not_finite, "inf"); });
  EXPECT_NE(message.find("vertex 3 = (0, 0, inf)"), std::string::npos) << message;
}

// Reference: a closed mesh with one face written twice has three faces at each of its edges.
TEST(MeshTopology, DuplicateFaceMakesNonManifoldEdges) {
  TriangleMesh mesh = grbd::body::box_mesh(Vector3(1, 2, 3));
  mesh.F.conservativeResize(13, 3);
  mesh.F.row(12) = mesh.F.row(5);
  const MeshTopology t = analyse_topology(mesh);
  EXPECT_EQ(t.non_manifold_edges, 3U);
  EXPECT_EQ(t.boundary_edges + t.inconsistent_edges + t.degenerate_faces + t.invalid_indices, 0U);
}

// ----------------------------------------------------------------------------------------------
// Mesh generators
// ----------------------------------------------------------------------------------------------

namespace {

/// Checks the properties every generated mesh must have: closed, oriented, the given Euler
/// characteristic, and every face normal pointing away from `inside(centroid)`, a point inside
/// the solid chosen for the face's centroid (the centre of a convex solid, the nearest point of
/// the centre line of a torus).
template <class Inside>
void expect_closed_outward(const TriangleMesh& mesh, long euler, Inside inside,
                           const std::string& what) {
  const MeshTopology t = analyse_topology(mesh);
  EXPECT_TRUE(t.closed_oriented_manifold())
      << what << ": boundary " << t.boundary_edges << ", non-manifold " << t.non_manifold_edges
      << ", inconsistent " << t.inconsistent_edges << ", degenerate " << t.degenerate_faces;
  EXPECT_NO_THROW(require_closed_oriented(mesh, what));
  EXPECT_EQ(euler_characteristic(mesh), euler) << what;
  int inward = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Vector3 centroid = face_centroid(mesh, f);
    if (!(face_normal(mesh, f).dot(centroid - inside(centroid)) > 0.0)) ++inward;
  }
  EXPECT_EQ(inward, 0) << what << ": faces whose normal points inward";
}

const auto origin = [](const Vector3&) -> Vector3 { return Vector3::Zero(); };

}  // namespace

// Reference: the box [−a, a] × [−b, b] × [−c, c]: 8 corners, 12 triangles, volume 8abc, every
// face on one of the six planes with its normal along the outward axis.
TEST(MeshGenerators, BoxIsClosedOutwardWithExactVolume) {
  const Vector3 h(0.3, 1.1, 2.5);
  const TriangleMesh mesh = grbd::body::box_mesh(h);
  EXPECT_EQ(mesh.V.rows(), 8);
  EXPECT_EQ(mesh.F.rows(), 12);
  expect_closed_outward(mesh, 2, origin, "box");
  EXPECT_NEAR(signed_volume(mesh), 8.0 * h.prod(), 1e-15 * 8.0 * h.prod());
  for (Eigen::Index i = 0; i < 8; ++i) {
    EXPECT_EQ(mesh.V.row(i).cwiseAbs(), h.transpose()) << "corner " << i;
  }
  for (Eigen::Index f = 0; f < 12; ++f) {
    const Vector3 n = face_normal(mesh, f).normalized();
    EXPECT_NEAR(n.cwiseAbs().maxCoeff(), 1.0, 1e-15) << "face " << f;  // along an axis
  }
}

// Reference: the volume of a tetrahedron, |(b − a)·((c − a) × (d − a))|/6, for every one of the
// 24 orders of its vertices: the generator must orient it outward whatever the order.
TEST(MeshGenerators, TetrahedronIsOutwardForEveryVertexOrder) {
  grbd::test::Random rng(2003);
  for (int sample = 0; sample < 20; ++sample) {
    std::array<Vector3, 4> p = {rng.vector3(), rng.vector3(), rng.vector3(), rng.vector3()};
    const double volume = std::abs((p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]))) / 6.0;
    // The triple product cancels digits for flat tetrahedra: its round-off is relative to the
    // product of the edge lengths, not to the volume.
    const double scale = (p[1] - p[0]).norm() * (p[2] - p[0]).norm() * (p[3] - p[0]).norm();
    std::array<int, 4> order = {0, 1, 2, 3};
    do {
      const TriangleMesh mesh =
          grbd::body::tetrahedron_mesh(p[order[0]], p[order[1]], p[order[2]], p[order[3]]);
      const Vector3 centre = (p[0] + p[1] + p[2] + p[3]) / 4.0;
      expect_closed_outward(
          mesh, 2, [&](const Vector3&) { return centre; }, "tetrahedron");
      EXPECT_NEAR(signed_volume(mesh), volume, 1e-14 * scale);
    } while (std::next_permutation(order.begin(), order.end()));
  }
}

// Reference: four points in one plane (exactly, and up to round-off after a rotation) span no
// volume.
TEST(MeshGenerators, TetrahedronRejectsCoplanarPoints) {
  EXPECT_THROW(grbd::body::tetrahedron_mesh(Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(0, 1, 0),
                                            Vector3(1, 1, 0)),
               grbd::InvalidArgument);
  grbd::test::Random rng(2004);
  for (int sample = 0; sample < 100; ++sample) {
    const Matrix3 A = rng.rotation();
    auto in_plane = [&] { return Vector3(A * Vector3(rng.uniform(), rng.uniform(), 0.0)); };
    EXPECT_THROW(grbd::body::tetrahedron_mesh(in_plane(), in_plane(), in_plane(), in_plane()),
                 grbd::InvalidArgument);
  }
  EXPECT_THROW(grbd::body::tetrahedron_mesh(Vector3::Zero(), Vector3(std::nan(""), 0, 0),
                                            Vector3(0, 1, 0), Vector3(0, 0, 1)),
               grbd::InvalidArgument);
}

// Reference: subdividing the icosahedron k times gives 10·4^k + 2 vertices and 20·4^k faces
// (Euler: V − E + F = 2), every vertex on the sphere |x| = R, and an inscribed polyhedron whose
// volume grows towards 4/3 π R³.
TEST(MeshGenerators, IcosphereIsInscribedClosedAndOutward) {
  const double R = 0.7;
  double previous_volume = 0.0;
  for (int k = 0; k <= 4; ++k) {
    const TriangleMesh mesh = grbd::body::icosphere_mesh(R, k);
    const long four_k = 1L << (2 * k);
    EXPECT_EQ(mesh.V.rows(), 10 * four_k + 2);
    EXPECT_EQ(mesh.F.rows(), 20 * four_k);
    expect_closed_outward(mesh, 2, origin, "icosphere " + std::to_string(k));
    const double radius_error = (mesh.V.rowwise().norm().array() - R).abs().maxCoeff();
    EXPECT_LE(radius_error, 1e-15) << "level " << k;
    const double volume = signed_volume(mesh);
    EXPECT_GT(volume, previous_volume) << "level " << k;
    EXPECT_LT(volume, 4.0 / 3.0 * pi * R * R * R) << "level " << k;
    previous_volume = volume;
  }
}

// Reference: the implicit equation of the torus, (√(x² + y²) − R)² + z² = r², with Euler
// characteristic 0 (genus 1) and 2·n_major·n_minor faces, normals pointing away from the tube's
// centre line.
TEST(MeshGenerators, TorusIsClosedOutwardAndOnTheSurface) {
  const double R = 1.3;
  const double r = 0.45;
  const TriangleMesh mesh = grbd::body::torus_mesh(R, r, 24, 10);
  EXPECT_EQ(mesh.V.rows(), 240);
  EXPECT_EQ(mesh.F.rows(), 480);
  const auto centre_line = [R](const Vector3& x) -> Vector3 {
    const double rho = std::hypot(x.x(), x.y());
    return Vector3(R * x.x() / rho, R * x.y() / rho, 0.0);
  };
  expect_closed_outward(mesh, 0, centre_line, "torus");
  WorstCase worst;
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    const double rho = std::hypot(mesh.V(i, 0), mesh.V(i, 1));
    worst.update(std::abs((rho - R) * (rho - R) + mesh.V(i, 2) * mesh.V(i, 2) - r * r),
                 [&] { return describe("vertex", i, "V", mesh.V.row(i)); });
  }
  EXPECT_LE(worst.value(), 1e-15) << worst;
  EXPECT_GT(signed_volume(mesh), 0.0);
  EXPECT_LT(signed_volume(mesh), 2.0 * pi * pi * R * r * r);  // inscribed in each section
}

// Reference: the cylinder x² + y² = R², |z| ≤ h/2: 2n + 2 vertices, 4n faces, χ = 2, normals
// pointing away from the axis (sides) or along ±z (caps); the volume of the inscribed regular
// n-gon prism, (n/2) R² sin(2π/n) h.
TEST(MeshGenerators, CylinderIsClosedOutwardAndAnInscribedPrism) {
  const double R = 0.8;
  const double h = 2.1;
  for (const int n : {3, 4, 7, 32}) {
    const TriangleMesh mesh = grbd::body::cylinder_mesh(R, h, n);
    EXPECT_EQ(mesh.V.rows(), 2 * n + 2);
    EXPECT_EQ(mesh.F.rows(), 4 * n);
    expect_closed_outward(mesh, 2, origin, "cylinder " + std::to_string(n));
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
      const Vector3 n_f = face_normal(mesh, f).normalized();
      const Vector3 c = face_centroid(mesh, f);
      if (std::abs(std::abs(c.z()) - 0.5 * h) < 1e-12) {
        EXPECT_NEAR(n_f.z(), c.z() > 0.0 ? 1.0 : -1.0, 1e-15) << "cap face " << f;
      } else {
        EXPECT_NEAR(n_f.z(), 0.0, 1e-15) << "side face " << f;  // vertical, pointing out
      }
    }
    const double prism = 0.5 * n * R * R * std::sin(2.0 * pi / n) * h;
    EXPECT_NEAR(signed_volume(mesh), prism, 1e-14 * prism) << "n = " << n;
  }
}

// Reference: the preconditions of the generators.
TEST(MeshGenerators, RejectInvalidArguments) {
  using grbd::InvalidArgument;
  namespace b = grbd::body;
  const double nan = std::nan("");
  EXPECT_THROW(b::box_mesh(Vector3(1, 0, 1)), InvalidArgument);
  EXPECT_THROW(b::box_mesh(Vector3(1, -1, 1)), InvalidArgument);
  EXPECT_THROW(b::box_mesh(Vector3(1, 1, nan)), InvalidArgument);
  EXPECT_THROW(b::icosphere_mesh(0.0, 2), InvalidArgument);
  EXPECT_THROW(b::icosphere_mesh(1.0, -1), InvalidArgument);
  EXPECT_THROW(b::icosphere_mesh(1.0, 11), InvalidArgument);
  EXPECT_THROW(b::torus_mesh(1.0, 1.0, 8, 8), InvalidArgument);  // r = R: not r < R
  EXPECT_THROW(b::torus_mesh(1.0, 0.0, 8, 8), InvalidArgument);
  EXPECT_THROW(b::torus_mesh(1.0, 0.5, 2, 8), InvalidArgument);
  EXPECT_THROW(b::torus_mesh(1.0, 0.5, 8, 2), InvalidArgument);
  EXPECT_THROW(b::torus_mesh(1.0, 0.5, 1 << 20, 1 << 20), InvalidArgument);
  EXPECT_THROW(b::cylinder_mesh(-1.0, 1.0, 8), InvalidArgument);
  EXPECT_THROW(b::cylinder_mesh(1.0, 0.0, 8), InvalidArgument);
  EXPECT_THROW(b::cylinder_mesh(1.0, 1.0, 2), InvalidArgument);
}

// ----------------------------------------------------------------------------------------------
// transformed
// ----------------------------------------------------------------------------------------------

// Reference: the definition x ↦ A x + r, vertex by vertex, with the same faces; a rotation keeps
// the signed volume and the topology.
TEST(MeshTransform, RigidMotionMapsEveryVertexAndKeepsTheFaces) {
  grbd::test::Random rng(2005);
  const TriangleMesh mesh = grbd::body::torus_mesh(1.0, 0.3, 16, 8);
  const double volume = signed_volume(mesh);
  for (int sample = 0; sample < 20; ++sample) {
    const Matrix3 A = rng.rotation();
    const Vector3 r = rng.vector3(-5, 5);
    const TriangleMesh image = grbd::body::transformed(mesh, A, r);
    EXPECT_EQ(image.F, mesh.F);
    WorstCase worst;
    for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
      const Vector3 expected = A * mesh.V.row(i).transpose() + r;
      worst.update((image.V.row(i).transpose() - expected).cwiseAbs().maxCoeff(), [&] {
        return describe("sample", sample, "A", A, "r", r, "vertex", i, "V", mesh.V.row(i));
      });
    }
    EXPECT_LE(worst.value(), 1e-15 * 8.0) << worst;  // |x| ≤ 6.3: a few ulps
    EXPECT_TRUE(analyse_topology(image).closed_oriented_manifold());
    EXPECT_NEAR(signed_volume(image), volume, 1e-13 * volume);
  }
}

// Reference: a reflection (det A < 0) would turn every face inward; a singular or non-finite
// map is no motion.
TEST(MeshTransform, RejectsReflectionsAndSingularMaps) {
  const TriangleMesh mesh = grbd::body::box_mesh(Vector3(1, 1, 1));
  EXPECT_THROW(
      grbd::body::transformed(mesh, Matrix3(Vector3(1, 1, -1).asDiagonal()), Vector3::Zero()),
      grbd::InvalidArgument);
  EXPECT_THROW(grbd::body::transformed(mesh, Matrix3::Zero(), Vector3::Zero()),
               grbd::InvalidArgument);
  EXPECT_THROW(grbd::body::transformed(mesh, Matrix3::Identity(), Vector3(0, std::nan(""), 0)),
               grbd::InvalidArgument);
}
