// Rejected input, one test per failure: each must fail with one line naming the file (and the
// line or element), never crash, hang or allocate in proportion to a count in a header. Ends
// with a deterministic mutation loop over all readers (run it under the sanitizer build).
#include "io/io_common.h"
#include "io_test_util.h"

#include <gtest/gtest.h>

#include <chrono>

using namespace quadlod;
using namespace quadlod::io_test;

namespace {

ReadResult obj(const std::string& text) { return parse_obj(text, "bad.obj"); }

// The error is a single line that names the file and, for text formats, the line.
void expect_error(const ReadResult& r, const std::string& where, const std::string& what) {
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.error.find('\n'), std::string::npos) << r.error;
  EXPECT_EQ(r.error.rfind(where, 0), 0u) << "error does not start with '" << where << "': " << r.error;
  EXPECT_NE(r.error.find(what), std::string::npos) << "'" << what << "' not in: " << r.error;
  EXPECT_EQ(r.mesh.num_faces(), 0u);  // a failed read hands back no partial mesh
}

const char* kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

std::string binary_ply(Index n) {
  PolyMesh m = quad_grid(n, n);
  m.uv_sets.clear();  // 12 bytes per vertex, 17 per quad
  std::string out, error;
  EXPECT_TRUE(io_detail::format_ply(m, {}, out, error)) << error;
  return out;
}

}  // namespace

TEST(ObjBadInput, TruncatedFile) {
  // OBJ has no counts, so a cut shows up as a broken last statement (or as no faces).
  expect_error(obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1 1"), "bad.obj:5:", "vertex has 2 coordinates");
  expect_error(obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 1 3"), "bad.obj:6:", "has 2 corners");
  expect_error(obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/"), "bad.obj:4:", "has 1 corner ");
  expect_error(obj("v 0 0 0\nv 1 0 0\nv 0"), "bad.obj", "vertex has 1 coordinates");
  expect_error(obj("v 0 0 0\nv 1 0 0\nv 0 1 0\n"), "bad.obj", "no faces");
}

TEST(PlyBadInput, TruncatedBinaryFile) {
  const std::string full = binary_ply(10);  // 121 vertices, 100 faces
  ASSERT_TRUE(io_detail::parse_ply(full, "t.ply").ok());
  const std::size_t header = full.find("end_header\n") + 11;
  // Inside the vertex block: 12 bytes per vertex.
  expect_error(io_detail::parse_ply(full.substr(0, header + 12 * 37 + 5), "t.ply"), "t.ply: ",
               "truncated: expected 121 vertices, file ends at 37");
  // Inside the face block: 17 bytes per quad.
  expect_error(io_detail::parse_ply(full.substr(0, header + 12 * 121 + 17 * 60 + 3), "t.ply"), "t.ply: ",
               "truncated: expected 100 faces, file ends at 60");
  // Through the file API the message names the path.
  TempDir dir;
  write_bytes(dir / "cut.ply", full.substr(0, full.size() - 1));
  const ReadResult r = read_ply(dir / "cut.ply");
  expect_error(r, (dir / "cut.ply").string() + ": ", "file ends at 99");
}

TEST(PlyBadInput, TruncatedAsciiFile) {
  WriteOptions o;
  o.ply_encoding = PlyEncoding::Ascii;
  std::string full, error;
  ASSERT_TRUE(io_detail::format_ply(quad_grid(3, 3), o, full, error));
  const std::string without_last_line = full.substr(0, full.rfind('\n', full.size() - 2) + 1);
  expect_error(io_detail::parse_ply(without_last_line, "a.ply"), "a.ply: ",
               "truncated: expected 9 faces, file ends at 8");
}

TEST(PlyBadInput, HeaderCountsCannotForceAllocation) {
  // 4e9 vertices and faces announced in a file of a few hundred bytes: must fail at once.
  const auto start = std::chrono::steady_clock::now();
  for (const char* format : {"ascii", "binary_little_endian"}) {
    const std::string text = std::string("ply\nformat ") + format +
                             " 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
                             "property float z\nelement face 4000000000\n"
                             "property list uchar int vertex_indices\nend_header\n0 0 0 1 1 1 2 2 2 3 3 3";
    expect_error(io_detail::parse_ply(text, "huge.ply"), "huge.ply: ", "truncated: expected 4000000000 vertices");
  }
  // A list claiming 4e9 entries.
  std::string text =
      "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n";
  text += std::string("\x00\x28\x6b\xee", 4);  // 4e9, little endian
  text += std::string(16, '\0');
  expect_error(io_detail::parse_ply(text, "list.ply"), "list.ply: ", "truncated: expected 1 faces, file ends at 0");
  // Counts beyond 32-bit indices.
  expect_error(io_detail::parse_ply("ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty float x\n"
                                    "property float y\nproperty float z\nend_header\n",
                                    "big.ply"),
               "big.ply: ", "too many vertices");
  expect_error(io_detail::parse_off("OFF\n4000000000 4000000000 0\n0 0 0\n", "huge.off"), "huge.off:", "file ends after 1 of 4000000000 vertices");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

TEST(PlyBadInput, MalformedHeaders) {
  expect_error(io_detail::parse_ply("solid x\n", "h.ply"), "h.ply:1:", "not a PLY file");
  expect_error(io_detail::parse_ply("ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n", "h.ply"),
               "h.ply:4:", "unknown property type 'quad'");
  expect_error(io_detail::parse_ply("ply\nformat ascii 1.0\nproperty float x\nend_header\n", "h.ply"), "h.ply:3:",
               "property before any element");
  expect_error(io_detail::parse_ply("ply\nformat ascii 1.0\nelement vertex 1\n", "h.ply"), "h.ply:", "no end_header");
  expect_error(io_detail::parse_ply("ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\nend_header\n", "h.ply"),
               "h.ply:4:", "list count type must be an integer type");
  expect_error(io_detail::parse_ply("ply\nformat binary_middle_endian 1.0\nend_header\n", "h.ply"), "h.ply:2:",
               "unknown format");
  expect_error(io_detail::parse_ply("ply\nformat ascii 1.0\nelement vertex -3\nend_header\n", "h.ply"), "h.ply:3:",
               "element line needs a name and a count");
  expect_error(io_detail::parse_ply("ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int idx\nend_header\n3 0 1 2\n", "h.ply"),
               "h.ply: ", "no vertex_indices list");
}

TEST(IoBadInput, GarbageBytes) {
  std::mt19937 rng(1);
  std::string garbage(4096, '\0');
  for (char& c : garbage) c = static_cast<char>(rng());
  TempDir dir;
  for (const char* name : {"g.obj", "g.ply", "g.off"}) {
    write_bytes(dir / name, garbage);
    const ReadResult r = read_mesh(dir / name);
    expect_error(r, (dir / name).string(), "");
  }
  expect_error(obj(std::string("v 0 0 0\nv 1 0 0\n\x01\x02\x00\x7f", 20)), "bad.obj:3:", "NUL byte");
  expect_error(obj("\x89PNG\r\n\x1a\n garbage garbage"), "bad.obj", "no faces");
}

TEST(ObjBadInput, NonNumericCoordinate) {
  expect_error(obj("v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n"), "bad.obj:2:", "bad number 'zero' in vertex");
  expect_error(obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 abc\nf 1 2 3\n"), "bad.obj:4:", "bad number 'abc'");
  expect_error(obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3x\n"), "bad.obj:4:", "bad face corner '3x'");
  expect_error(obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/a\n"), "bad.obj:4:", "bad face corner");
  expect_error(obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\ns maybe\n"), "bad.obj:5:", "bad smoothing group");
}

TEST(IoBadInput, NanAndInfCoordinates) {
  expect_error(obj("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), "bad.obj:2:", "non-finite value 'nan'");
  expect_error(obj("v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n"), "bad.obj:3:", "non-finite value '-inf'");
  expect_error(obj("v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n"), "bad.obj:2:", "bad number '1e999'");
  expect_error(obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 NaN 1\nf 1 2 3\n"), "bad.obj:4:", "non-finite");
  expect_error(io_detail::parse_ply("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                    "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                    "end_header\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n",
                                    "n.ply"),
               "n.ply: ", "vertex 1: non-finite coordinate");
  expect_error(io_detail::parse_off("OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n", "n.off"), "n.off:4:",
               "vertex 1: non-finite coordinate");
}

TEST(IoBadInput, IndexOutOfRange) {
  // Positive: checked after the whole file; the message names the face's line.
  expect_error(obj(std::string(kTriangle) + "f 1 2 3\nf 1 2 4\nv 1 1 1\nf 1 2 5\n"), "bad.obj:7:",
               "face refers to vertex 5 but only 4 are defined");
  expect_error(obj(std::string(kTriangle) + "vt 0 0\nf 1/1 2/2 3/1\n"), "bad.obj:5:",
               "face refers to texture coordinate 2 but only 1 are defined");
  expect_error(obj(std::string(kTriangle) + "f 1//1 2//1 3//1\n"), "bad.obj:4:", "normal 1 but only 0");
  // Negative: relative to what is defined so far.
  expect_error(obj(std::string(kTriangle) + "f -1 -2 -4\n"), "bad.obj:4:",
               "face refers to vertex -4 but only 3 are defined before it");
  expect_error(obj(std::string(kTriangle) + "f 1 2 99999999999\n"), "bad.obj:4:", "beyond the 32-bit index range");
  expect_error(io_detail::parse_ply("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                    "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
                                    "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 99\n",
                                    "mesh.ply"),
               "mesh.ply: ", "face 1: vertex index 99 out of range (3 vertices)");
  expect_error(io_detail::parse_ply("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                    "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                    "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -2\n",
                                    "mesh.ply"),
               "mesh.ply: ", "face 0: bad vertex index");
  expect_error(io_detail::parse_off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "m.off"), "m.off:6:",
               "face 0: vertex index 3 out of range (3 vertices)");
}

TEST(ObjBadInput, IndexZero) {
  expect_error(obj(std::string(kTriangle) + "f 0 1 2\n"), "bad.obj:4:", "vertex 0 (OBJ indices start at 1)");
  expect_error(obj(std::string(kTriangle) + "vt 0 0\nf 1/0 2/1 3/1\n"), "bad.obj:5:", "texture coordinate 0");
}

TEST(IoBadInput, EmptyMesh) {
  expect_error(obj(""), "bad.obj", "no faces");
  expect_error(obj("# only a comment\n\n"), "bad.obj", "no faces");
  expect_error(obj(kTriangle), "bad.obj", "no faces");
  expect_error(io_detail::parse_ply("ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
                                    "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n",
                                    "e.ply"),
               "e.ply: ", "no faces");
  expect_error(io_detail::parse_off("OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", "e.off"), "e.off", "no faces");
  expect_error(io_detail::parse_off("", "e.off"), "e.off:", "no OFF header");
  TempDir dir;
  write_bytes(dir / "empty.obj", "");
  expect_error(read_obj(dir / "empty.obj"), (dir / "empty.obj").string(), "no faces");
}

TEST(IoBadInput, FaceUsingAVertexTwice) {
  expect_error(obj(std::string(kTriangle) + "v 1 1 0\nf 1 2 3 -3\n"), "bad.obj:5:", "face uses vertex 2 more than once");
  std::string big = std::string(kTriangle);
  for (int i = 0; i < 30; ++i) big += "v " + std::to_string(i) + " 5 0\n";
  big += "f";
  for (int i = 1; i <= 33; ++i) big += " " + std::to_string(i);
  big += " 17\n";  // the sort path for large n-gons
  expect_error(obj(big), "bad.obj:34:", "face uses vertex 17 more than once");
  expect_error(io_detail::parse_ply("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                    "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                    "end_header\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2 0\n",
                                    "r.ply"),
               "r.ply: ", "face 0: uses vertex 0 more than once");
  expect_error(io_detail::parse_off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 1\n", "r.off"), "r.off:6:",
               "uses vertex 1 more than once");
}

TEST(IoBadInput, FaceWithTooFewCorners) {
  expect_error(obj(std::string(kTriangle) + "f 1 2\n"), "bad.obj:4:", "face has 2 corners (at least 3 needed)");
  expect_error(obj(std::string(kTriangle) + "f\n"), "bad.obj:4:", "face has 0 corners");
  expect_error(io_detail::parse_off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "f.off"), "f.off:6:", "has 2 corners");
}

TEST(IoBadInput, OutputPathInMissingDirectory) {
  TempDir dir;
  const fs::path target = dir / "missing" / "x.obj";
  const WriteResult w = write_mesh(quad_grid(2, 2), target);
  EXPECT_EQ(w.error, "cannot write " + target.string() + ": directory does not exist");
  EXPECT_FALSE(fs::exists(dir / "missing"));
  EXPECT_TRUE(dir.entries().empty());  // neither the target nor a temporary file
  for (const char* name : {"x.ply", "x.off"}) EXPECT_FALSE(write_mesh(quad_grid(2, 2), dir / "missing" / name).ok());
  EXPECT_FALSE(write_file_atomically(dir / "missing" / "report.json", "{}").ok());
  EXPECT_TRUE(dir.entries().empty());
}

TEST(IoBadInput, UnsupportedOffVariants) {
  expect_error(io_detail::parse_off("OFF BINARY\n", "b.off"), "b.off:1:", "OFF BINARY is not supported");
  expect_error(io_detail::parse_off("nOFF\n4\n", "b.off"), "b.off:1:", "nOFF");
  expect_error(io_detail::parse_off("PLY\n", "b.off"), "b.off:1:", "not an OFF file");
  expect_error(io_detail::parse_off("OFF\nthree 1 0\n", "b.off"), "b.off:2:", "bad counts line");
  expect_error(io_detail::parse_off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", "b.off"), "b.off:6:", "announced");
}

// Deterministic mutations of valid files through every reader: flipped bytes, cuts, inserted
// and duplicated spans. A reader may accept or reject, but an accepted mesh must satisfy the
// layout invariants and a rejection must be one line naming the file.
TEST(IoFuzz, MutatedInputsNeverCrash) {
  PolyMesh seed_mesh = quad_grid(3, 2);
  seed_mesh.add_face({0, 5, 6, 7, 1});
  seed_mesh.normals = {Vec3(0, 0, 1)};
  seed_mesh.corner_normal.assign(seed_mesh.num_corners(), 0);
  seed_mesh.material_names = {"m"};
  seed_mesh.face_material.assign(seed_mesh.num_faces(), 0);

  struct Seed {
    std::string name, bytes;
  };
  std::vector<Seed> seeds;
  std::string out, error;
  ASSERT_TRUE(io_detail::format_obj(seed_mesh, {}, out, error));
  seeds.push_back({"f.obj", out + "f -1 -2 -3\nl 1 2\ns 1\ng a b\n"});
  ASSERT_TRUE(io_detail::format_off(seed_mesh, {}, out, error));
  seeds.push_back({"f.off", out});
  for (PlyEncoding e : {PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian, PlyEncoding::BinaryBigEndian}) {
    WriteOptions o;
    o.ply_encoding = e;
    ASSERT_TRUE(io_detail::format_ply(seed_mesh, o, out, error));
    seeds.push_back({"f.ply", out});
  }

  std::mt19937_64 rng(12345);
  const char interesting[] = {'\n', '\r', ' ', '/', '-', '\\', '#', '0', '9', '.', 'e', '\0', '\xff', 'f', 'v'};
  int accepted = 0, rejected = 0;
  for (const Seed& seed : seeds) {
    for (int iteration = 0; iteration < 1500; ++iteration) {
      std::string s = seed.bytes;
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < edits && !s.empty(); ++k) {
        const std::size_t at = rng() % s.size();
        switch (rng() % 5) {
          case 0: s[at] = static_cast<char>(rng()); break;
          case 1: s[at] = interesting[rng() % sizeof interesting]; break;
          case 2: s.resize(at); break;
          case 3: s.insert(at, 1 + rng() % 8, interesting[rng() % sizeof interesting]); break;
          case 4: s.insert(at, s.substr(rng() % s.size(), rng() % 32)); break;
        }
      }
      const std::string ext = seed.name.substr(seed.name.size() - 3);
      const ReadResult r = ext == "obj"   ? parse_obj(s, seed.name)
                           : ext == "ply" ? io_detail::parse_ply(s, seed.name)
                                          : io_detail::parse_off(s, seed.name);
      if (r.ok()) {
        ASSERT_EQ(r.mesh.check_layout(), "") << seed.name << " iteration " << iteration;
        ASSERT_GT(r.mesh.num_faces(), 0u);
        ++accepted;
      } else {
        ASSERT_EQ(r.error.rfind(seed.name, 0), 0u) << r.error;
        ASSERT_EQ(r.error.find('\n'), std::string::npos) << r.error;
        ++rejected;
      }
    }
  }
  EXPECT_GT(accepted, 0);
  EXPECT_GT(rejected, 0);
}
