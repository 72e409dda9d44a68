// OBJ / PLY / OFF readers and writers against hand-written files with known answers, exact
// round trips in every format and encoding, dispatch, atomic writes, and the corpus.
#include "io/io_common.h"
#include "io_test_util.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstring>

using namespace quadlod;
using namespace quadlod::io_test;

namespace {

ReadResult obj(const std::string& text, const ReadOptions& options = {}) {
  return parse_obj(text, "t.obj", options);
}

std::vector<Index> corners(const PolyMesh& m) { return m.corner_vertex; }
std::vector<Index> offsets(const PolyMesh& m) { return m.face_offsets; }

constexpr Index X = kInvalidIndex;

const char* kSquareVerts =
    "v 0 0 0\n"
    "v 1 0 0\n"
    "v 1 1 0\n"
    "v 0 1 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "vn 0 0 1\nvn 0 0 -1\n";

}  // namespace

// --- OBJ reader: face forms ---------------------------------------------------------------

TEST(ObjRead, PlainFaceFormKeepsQuadAndTriangle) {
  const ReadResult r = obj(std::string(kSquareVerts) + "f 1 2 3 4\nf 1 3 4\n");
  ASSERT_TRUE(r.ok()) << r.error;
  const PolyMesh& m = r.mesh;
  EXPECT_EQ(m.num_vertices(), 4u);
  EXPECT_EQ(m.num_faces(), 2u);
  EXPECT_EQ(offsets(m), (std::vector<Index>{0, 4, 7}));
  EXPECT_EQ(corners(m), (std::vector<Index>{0, 1, 2, 3, 0, 2, 3}));
  EXPECT_EQ(m.positions[2], Vec3(1, 1, 0));
  EXPECT_TRUE(m.uv_sets.empty());  // a `vt` pool no face uses is not a UV set
  EXPECT_EQ(m.normals.size(), 2u);
  EXPECT_FALSE(m.has_uvs());
  EXPECT_FALSE(m.has_normals());
  EXPECT_TRUE(m.face_object.empty() && m.face_group.empty() && m.face_material.empty() &&
              m.face_smoothing.empty());
  EXPECT_EQ(m.check_layout(), "");
}

TEST(ObjRead, VertexTexcoordForm) {
  const ReadResult r = obj(std::string(kSquareVerts) + "f 1/4 2/3 3/2 4/1\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.uv_sets[0].corner, (std::vector<Index>{3, 2, 1, 0}));
  EXPECT_FALSE(r.mesh.has_normals());
}

TEST(ObjRead, VertexNormalForm) {
  const ReadResult r = obj(std::string(kSquareVerts) + "f 1//2 2//1 3//1 4//2\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.corner_normal, (std::vector<Index>{1, 0, 0, 1}));
  EXPECT_FALSE(r.mesh.has_uvs());
}

TEST(ObjRead, VertexTexcoordNormalForm) {
  const ReadResult r = obj(std::string(kSquareVerts) + "f 1/1/1 2/2/1 3/3/2 4/4/2\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.uv_sets[0].corner, (std::vector<Index>{0, 1, 2, 3}));
  EXPECT_EQ(r.mesh.corner_normal, (std::vector<Index>{0, 0, 1, 1}));
}

TEST(ObjRead, CornersWithoutTexcoordGetInvalidIndex) {
  // The first face has no vt at all: its corners are back-filled when the array appears.
  const ReadResult r = obj(std::string(kSquareVerts) + "f 1 2 3\nf 1/1 3 4/4/\nf 2//1 3/2/ 4\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.uv_sets[0].corner, (std::vector<Index>{X, X, X, 0, X, 3, X, 1, X}));
  EXPECT_EQ(r.mesh.corner_normal, (std::vector<Index>{X, X, X, X, X, X, 0, X, X}));
  EXPECT_EQ(r.mesh.check_layout(), "");
}

TEST(ObjRead, NegativeIndicesAreRelativeToWhatIsDefinedSoFar) {
  const ReadResult r = obj(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
      "f -3/-3 -2/-2 -1/-1\n"
      "v 0 1 0\nvt 0 1\nvn 0 0 1\n"
      "f -4/-1/-1 -2/-2/-1 -1/-1/-1\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(corners(r.mesh), (std::vector<Index>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(r.mesh.uv_sets[0].corner, (std::vector<Index>{0, 1, 2, 3, 2, 3}));
  EXPECT_EQ(r.mesh.corner_normal, (std::vector<Index>{X, X, X, 0, 0, 0}));
}

TEST(ObjRead, PositiveIndicesMayReferForward) {
  const ReadResult r = obj("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.num_faces(), 1u);
}

TEST(ObjRead, CrlfLineEnds) {
  const ReadResult r = obj("v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nvt 0.5 0.25\r\ng body\r\nf 1/1 2/1 3/1\r\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.positions[1], Vec3(1, 0, 0));
  EXPECT_EQ(r.mesh.uv_sets[0].values[0], Vec2(0.5, 0.25));
  ASSERT_EQ(r.mesh.group_names.size(), 1u);
  EXPECT_EQ(r.mesh.group_names[0], "body");  // no '\r' in the name
}

TEST(ObjRead, TrailingBackslashContinuesTheStatement) {
  const ReadResult r = obj("v 0 0 0\nv 1 0 \\\n 0\nv 1 1 0\nv 0 1 0\nf 1 2 \\\r\n3 \\\n4\n# a\\\nf 1 2 3\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.positions[1], Vec3(1, 0, 0));
  EXPECT_EQ(offsets(r.mesh), (std::vector<Index>{0, 4, 7}));  // the comment did not swallow f

  // Line numbers keep counting physical lines after a continuation.
  const ReadResult bad = obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 \\\n 2 \\\n 3\nv 1 2 x\n");
  EXPECT_NE(bad.error.find("t.obj:7:"), std::string::npos) << bad.error;
}

TEST(ObjRead, CommentsBlankLinesAndTrailingComments) {
  const ReadResult r = obj(
      "# header\n\n   \n\tv 0 0 0 # origin\nv 1 0 0\nv 0 1 0\n  # indented comment\n"
      "f 1 2 3 # a triangle\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.num_vertices(), 3u);
  EXPECT_EQ(r.mesh.num_faces(), 1u);
}

TEST(ObjRead, ObjectsGroupsMaterialsSmoothingAndLibraries) {
  const ReadResult r = obj(std::string("mtllib a.mtl b b.mtl\n") + kSquareVerts +
                           "f 1 2 3\n"                        // before any tag
                           "o Body\ng left  arm\nusemtl Material #25\ns 2\nf 1 2 3 4\n"
                           "g\nusemtl steel\ns off\nf 1 3 4\n"
                           "o Body\nusemtl Material #25\nmtllib c.mtl\ns 0\nf 2 3 4\n");
  ASSERT_TRUE(r.ok()) << r.error;
  const PolyMesh& m = r.mesh;
  EXPECT_EQ(m.material_libraries, (std::vector<std::string>{"a.mtl b b.mtl", "c.mtl"}));
  EXPECT_EQ(m.object_names, (std::vector<std::string>{"Body"}));
  EXPECT_EQ(m.group_names, (std::vector<std::string>{"left  arm", ""}));
  EXPECT_EQ(m.material_names, (std::vector<std::string>{"Material #25", "steel"}));
  EXPECT_EQ(m.face_object, (std::vector<Index>{X, 0, 0, 0}));
  EXPECT_EQ(m.face_group, (std::vector<Index>{X, 0, 1, 1}));
  EXPECT_EQ(m.face_material, (std::vector<Index>{X, 0, 1, 0}));
  EXPECT_EQ(m.face_smoothing, (std::vector<Index>{0, 2, 0, 0}));
  EXPECT_EQ(m.check_layout(), "");
}

TEST(ObjRead, NamesNoFaceUsesStayOutOfTheTables) {
  const ReadResult r = obj("usemtl unused\nusemtl used\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\ng late\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.material_names, (std::vector<std::string>{"used"}));
  EXPECT_TRUE(r.mesh.group_names.empty());
  EXPECT_TRUE(r.mesh.face_group.empty());
}

TEST(ObjRead, NGonsKeepTheirCornersInOrder) {
  std::string text;
  for (int i = 0; i < 40; ++i)
    text += "v " + std::to_string(std::cos(i * 0.157)) + " " + std::to_string(std::sin(i * 0.157)) + " 0\n";
  text += "f 1 2 3 4 5\nf 6 7 8 9 10 11\nf";
  for (int i = 40; i >= 1; --i) {
    text += ' ';
    text += std::to_string(i);
  }
  text += "\n";
  const ReadResult r = obj(text);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.num_faces(), 3u);
  EXPECT_EQ(r.mesh.face_size(0), 5u);
  EXPECT_EQ(r.mesh.face_size(1), 6u);
  EXPECT_EQ(r.mesh.face_size(2), 40u);
  EXPECT_EQ(r.mesh.face_vertices(2)[0], 39u);
  EXPECT_EQ(r.mesh.face_vertices(2)[39], 0u);
}

TEST(ObjRead, VertexWeightAndColours) {
  const ReadResult r = obj("v 1 2 3 1.0\nv 4 5 6 0.5 0.25 1\nv 7 8 9\nf 1 2 3\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.positions[0], Vec3(1, 2, 3));  // w dropped
  ASSERT_EQ(r.mesh.vertex_colors.size(), 3u);
  EXPECT_EQ(r.mesh.vertex_colors[0], Vec3(1, 1, 1));  // before the first colour: white
  EXPECT_EQ(r.mesh.vertex_colors[1], Vec3(0.5, 0.25, 1));
  EXPECT_EQ(r.mesh.vertex_colors[2], Vec3(1, 1, 1));
}

TEST(ObjRead, NumberForms) {
  const ReadResult r = obj("v +1.5 -2e-3 .25\nv 1E2 0x10 0\nv 0 0 0\nf 1 2 3\n");
  EXPECT_FALSE(r.ok());  // hexadecimal is not a coordinate
  const ReadResult ok = obj("v +1.5 -2e-3 .25\nv 1E2 -0 5.\nv 0 0 0\nvt 0.5\nvt 1 2 3\nf 1/1 2/2 3/1\n");
  ASSERT_TRUE(ok.ok()) << ok.error;
  EXPECT_EQ(ok.mesh.positions[0], Vec3(1.5, -2e-3, 0.25));
  EXPECT_EQ(ok.mesh.positions[1], Vec3(100, 0, 5));
  EXPECT_EQ(ok.mesh.uv_sets[0].values[0], Vec2(0.5, 0));  // missing v defaults to 0
  EXPECT_EQ(ok.mesh.uv_sets[0].values[1], Vec2(1, 2));    // w dropped
}

TEST(ObjRead, IgnoredStatementsAreSkippedAndCounted) {
  const ReadResult r = obj(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvp 0.5\nl 1 2\np 3\ncstype bspline\ndeg 3\ncurv 0 1 1 2\n"
      "end\nmaplib x\nf 1 2 3\nbevel off\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.num_faces(), 1u);
  EXPECT_EQ(r.ignored_records, 9u);
}

TEST(ObjRead, ByteOrderMarkAndFoKeyword) {
  const ReadResult r = obj("\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nfo 1 2 3\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.num_faces(), 1u);
}

TEST(ObjRead, RepeatedVertexAllowedOnRequest) {
  const std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 2\n";
  EXPECT_FALSE(obj(text).ok());
  ReadOptions allow;
  allow.allow_repeated_vertex = true;
  const ReadResult r = obj(text, allow);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(corners(r.mesh), (std::vector<Index>{0, 1, 2, 1}));
}

TEST(ObjRead, ReadObjFromFileTimesAndNamesThePath) {
  TempDir dir;
  write_bytes(dir / "a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const ReadResult r = read_obj(dir / "a.obj");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_GE(r.seconds, 0.0);
  const ReadResult missing = read_obj(dir / "nope.obj");
  EXPECT_NE(missing.error.find((dir / "nope.obj").string()), std::string::npos) << missing.error;
  EXPECT_NE(missing.error.find("No such file"), std::string::npos) << missing.error;
  fs::create_directory(dir / "sub.obj");
  const ReadResult directory = read_mesh(dir / "sub.obj");
  EXPECT_NE(directory.error.find("is a directory"), std::string::npos) << directory.error;
}

// --- OBJ writer and round trips -------------------------------------------------------------

TEST(ObjWrite, EmitsTheFormsAndTagsThatArePresent) {
  const ReadResult r = obj(std::string("mtllib m.mtl\n") + kSquareVerts +
                           "o A\nusemtl red\ns 1\nf 1/1/1 2/2/1 3/3/1\nf 1 3//2 4/4\nusemtl blue\nf 2 3 4\n");
  ASSERT_TRUE(r.ok()) << r.error;
  std::string out, error;
  ASSERT_TRUE(io_detail::format_obj(r.mesh, {}, out, error)) << error;
  const std::string expected =
      "# quadlod: 4 vertices, 3 faces\n"
      "mtllib m.mtl\n"
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
      "vn 0 0 1\nvn 0 0 -1\n"
      "o A\nusemtl red\ns 1\nf 1/1/1 2/2/1 3/3/1\n"
      "f 1 3//2 4/4\n"
      "usemtl blue\nf 2 3 4\n";
  EXPECT_EQ(out, expected);
}

TEST(ObjWrite, PrecisionControlsSignificantDigits) {
  PolyMesh m;
  m.positions = {Vec3(1.0 / 3.0, 2e-7, -12345.678901234), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  m.add_face({0, 1, 2});
  std::string out, error;
  WriteOptions o;
  o.precision = 4;
  ASSERT_TRUE(io_detail::format_obj(m, o, out, error));
  EXPECT_NE(out.find("v 0.3333 2e-07 -1.235e+04\n"), std::string::npos) << out;
  o.precision = 17;
  ASSERT_TRUE(io_detail::format_obj(m, o, out, error));
  const ReadResult back = parse_obj(out, "p.obj");
  ASSERT_TRUE(back.ok()) << back.error;
  EXPECT_EQ(back.mesh.positions[0], m.positions[0]);  // 17 digits round-trip doubles exactly
}

TEST(ObjWrite, RejectsAnInvalidMeshAndUnwritableNames) {
  TempDir dir;
  PolyMesh m;
  m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  m.add_face({0, 1, 5});
  const WriteResult w = write_obj(m, dir / "bad.obj");
  EXPECT_NE(w.error.find("bad.obj"), std::string::npos) << w.error;
  EXPECT_NE(w.error.find("out of range"), std::string::npos) << w.error;
  m.corner_vertex[2] = 2;
  m.group_names = {"two\nlines"};
  m.face_group = {0};
  EXPECT_FALSE(write_obj(m, dir / "bad.obj").ok());
  EXPECT_TRUE(dir.entries().empty());
}

TEST(ObjRoundTrip, HandWrittenFileWithEverything) {
  const std::string text = std::string("mtllib m.mtl\n") +
                           "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 0.5 0.5 0.5\nv 2 0 0 1 1 1\n"
                           "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.25 0.75\n"
                           "vn 0 0 1\nvn 0 0 -1\n"
                           "f 1 2 3\n"
                           "o A\ng g1 g2\nusemtl red\ns 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n"
                           "f 2/5 5/1 3//2\ng\ns off\nf 1//2 3//2 4//2\n"
                           "o B\nusemtl \ns 3\nf 2 5 3 4 1\n";
  const ReadResult a = obj(text);
  ASSERT_TRUE(a.ok()) << a.error;
  TempDir dir;
  ASSERT_TRUE(write_mesh(a.mesh, dir / "rt.obj").ok());
  const ReadResult b = read_mesh(dir / "rt.obj");
  ASSERT_TRUE(b.ok()) << b.error;
  EXPECT_EQ(mesh_difference(a.mesh, b.mesh), "");
}

TEST(ObjRoundTrip, FullPrecisionDoublesWithSeventeenDigits) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  PolyMesh m = quad_grid(6, 5);
  for (Vec3& p : m.positions) p = Vec3(u(rng), u(rng), u(rng) * 1e-9);
  for (Vec2& t : m.uv_sets[0].values) t = Vec2(u(rng), u(rng));
  WriteOptions o;
  o.precision = 17;
  TempDir dir;
  ASSERT_TRUE(write_obj(m, dir / "g.obj", o).ok());
  const ReadResult b = read_obj(dir / "g.obj");
  ASSERT_TRUE(b.ok()) << b.error;
  EXPECT_EQ(mesh_difference(m, b.mesh), "");
}

TEST(ObjRoundTrip, CorpusFilesAreReproducedExactly) {
  int tested = 0;
  for (const char* name : {"blender_suzanne.obj", "collada_duck.obj", "makehuman_base_body.obj",
                           "flightgear_shipyard_crane.obj"}) {
    const std::string path = corpus_file(name);
    if (path.empty()) continue;
    SCOPED_TRACE(name);
    const ReadResult a = read_obj(path);
    ASSERT_TRUE(a.ok()) << a.error;
    ASSERT_EQ(a.mesh.check_layout(), "");
    std::string out, error;
    ASSERT_TRUE(io_detail::format_obj(a.mesh, {}, out, error)) << error;
    const ReadResult b = parse_obj(out, name);
    ASSERT_TRUE(b.ok()) << b.error;
    EXPECT_EQ(mesh_difference(a.mesh, b.mesh), "");
    ++tested;
  }
  if (tested == 0) GTEST_SKIP() << "corpus not found";
}

TEST(ObjCorpus, CountsMatchTheCorpusReadme) {
  struct Expect {
    const char* name;
    Index vertices, faces, quads;
    bool uv, normals;
  };
  // Numbers from /work/shared/corpus/README.md (stats.py).
  const Expect expected[] = {{"blender_suzanne.obj", 507, 500, 468, true, false},
                             {"collada_duck.obj", 2108, 2144, 2052, true, true},
                             {"flightgear_cg57_cruiser_hd.obj", 112786, 86375, 77396, true, false},
                             {"assimp_suzanne_subdiv.obj", 126381, 125952, 125952, false, false}};
  int tested = 0;
  for (const Expect& e : expected) {
    const std::string path = corpus_file(e.name);
    if (path.empty()) continue;
    SCOPED_TRACE(e.name);
    const ReadResult r = read_mesh(path);
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.mesh.num_vertices(), e.vertices);
    EXPECT_EQ(r.mesh.num_faces(), e.faces);
    Index quads = 0;
    for (Index f = 0; f < r.mesh.num_faces(); ++f) quads += r.mesh.face_size(f) == 4;
    EXPECT_EQ(quads, e.quads);
    EXPECT_EQ(r.mesh.has_uvs(), e.uv);
    EXPECT_EQ(r.mesh.has_normals(), e.normals);
    EXPECT_EQ(r.mesh.check_layout(), "");
    ++tested;
  }
  if (tested == 0) GTEST_SKIP() << "corpus not found";
}

TEST(ObjCorpus, EveryCorpusFileReads) {
#ifdef QUADLOD_CORPUS_DIR
  const fs::path dir = QUADLOD_CORPUS_DIR;
  if (!fs::exists(dir)) GTEST_SKIP() << "corpus not found";
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".obj") continue;
    const ReadResult r = read_mesh(entry.path());
    EXPECT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.mesh.check_layout(), "") << entry.path();
    ++files;
  }
  EXPECT_GE(files, 30);
#else
  GTEST_SKIP() << "QUADLOD_CORPUS_DIR not defined";
#endif
}

// --- PLY --------------------------------------------------------------------------------------

namespace {

// Seams (two UVs on one vertex), an n-gon, colours and per-vertex normals: all that PLY carries.
PolyMesh ply_test_mesh() {
  PolyMesh m = quad_grid(3, 2);
  m.positions.emplace_back(0.123456789012, -7.5, 1e-3);  // not float-exact
  const Index extra = m.num_vertices() - 1;
  m.add_face({0, extra, 4, 5, 1});
  m.uv_sets[0].values.emplace_back(0.3, 0.7);
  for (Index c = m.face_begin(m.num_faces() - 1); c < m.num_corners(); ++c)
    m.uv_sets[0].corner[c] = static_cast<Index>(m.uv_sets[0].values.size() - 1);  // seam: vertex 0 has two UVs
  m.uv_sets[0].corner[m.num_corners() - 2] = kInvalidIndex;         // partial face
  for (Index v = 0; v < m.num_vertices(); ++v) {
    m.vertex_colors.emplace_back(v / 255.0, 1.0, 0.0);
    m.normals.push_back(Vec3(v, 1, 2).normalized());
  }
  m.corner_normal = m.corner_vertex;  // per-vertex normals: representable
  return m;
}

// True when b holds exactly the float nearest to each coordinate of a. Scalar on purpose:
// EXPECT_EQ on Eigen vectors built from cast<float>().cast<double>() reported false
// mismatches with g++ 12 at -O2/-O3 (values printed identical, operator== true).
template <class A, class B>
bool float_equal(const A& a, const B& b) {
  for (Eigen::Index k = 0; k < a.size(); ++k)
    if (static_cast<double>(static_cast<float>(a[k])) != static_cast<double>(b[k])) return false;
  return true;
}

void expect_same_after_ply(const PolyMesh& a, const PolyMesh& b) {
  ASSERT_EQ(b.check_layout(), "");
  ASSERT_EQ(a.num_vertices(), b.num_vertices());
  ASSERT_EQ(b.normals.size(), b.num_vertices());
  for (Index v = 0; v < a.num_vertices(); ++v) {
    EXPECT_TRUE(float_equal(a.positions[v], b.positions[v])) << "vertex " << v;
    EXPECT_TRUE(float_equal(a.normals[v], b.normals[v])) << "vertex " << v;  // pools per vertex
  }
  EXPECT_EQ(a.face_offsets, b.face_offsets);
  EXPECT_EQ(a.corner_vertex, b.corner_vertex);
  ASSERT_TRUE(b.has_uvs());
  for (Index c = 0; c < a.num_corners(); ++c) {
    const Index ta = a.uv_sets[0].corner[c], tb = b.uv_sets[0].corner[c];
    ASSERT_EQ(ta == kInvalidIndex, tb == kInvalidIndex) << "corner " << c;
    if (ta != kInvalidIndex) {
      EXPECT_TRUE(float_equal(a.uv_sets[0].values[ta], b.uv_sets[0].values[tb])) << "corner " << c;
    }
  }
  ASSERT_TRUE(b.has_normals());
  EXPECT_EQ(b.corner_normal, b.corner_vertex);
  ASSERT_EQ(b.vertex_colors.size(), a.vertex_colors.size());
  for (Index v = 0; v < a.num_vertices(); ++v)
    EXPECT_TRUE(b.vertex_colors[v].isApprox(a.vertex_colors[v], 1e-12) ||
                (b.vertex_colors[v] - a.vertex_colors[v]).cwiseAbs().maxCoeff() <= 0.5 / 255.0)
        << "vertex " << v;
}

std::string encoding_name(PlyEncoding e) {
  return e == PlyEncoding::Ascii ? "ascii" : e == PlyEncoding::BinaryLittleEndian ? "le" : "be";
}

}  // namespace

class PlyRoundTrip : public ::testing::TestWithParam<PlyEncoding> {};

TEST_P(PlyRoundTrip, GeometryFacesUvsNormalsColours) {
  const PolyMesh m = ply_test_mesh();
  ASSERT_EQ(m.check_layout(), "");
  TempDir dir;
  WriteOptions o;
  o.ply_encoding = GetParam();
  const WriteResult w = write_mesh(m, dir / "m.ply", o);
  ASSERT_TRUE(w.ok()) << w.error;
  const ReadResult r = read_mesh(dir / "m.ply");
  ASSERT_TRUE(r.ok()) << r.error;
  expect_same_after_ply(m, r.mesh);

  // A second trip is exact: everything is float already.
  ASSERT_TRUE(write_mesh(r.mesh, dir / "m2.ply", o).ok());
  const ReadResult r2 = read_mesh(dir / "m2.ply");
  ASSERT_TRUE(r2.ok()) << r2.error;
  EXPECT_EQ(mesh_difference(r.mesh, r2.mesh), "");
  EXPECT_EQ(read_bytes(dir / "m.ply"), read_bytes(dir / "m2.ply"));
}

TEST_P(PlyRoundTrip, LargeNGonUsesAWideCountType) {
  PolyMesh m;
  std::vector<Index> ring;
  for (Index i = 0; i < 300; ++i) {
    m.positions.emplace_back(std::cos(i * 0.0209), std::sin(i * 0.0209), 0.0);
    ring.push_back(i);
  }
  m.add_face(ring);
  m.add_face({0, 1, 2});
  TempDir dir;
  WriteOptions o;
  o.ply_encoding = GetParam();
  ASSERT_TRUE(write_ply(m, dir / "n.ply", o).ok());
  EXPECT_NE(read_bytes(dir / "n.ply").find("property list int int vertex_indices"), std::string::npos);
  const ReadResult r = read_ply(dir / "n.ply");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.face_offsets, m.face_offsets);
  EXPECT_EQ(r.mesh.corner_vertex, m.corner_vertex);
  EXPECT_FALSE(r.mesh.has_uvs());
  EXPECT_TRUE(r.mesh.vertex_colors.empty());
}

TEST_P(PlyRoundTrip, CorpusDuck) {
  const std::string path = corpus_file("collada_duck.obj");
  if (path.empty()) GTEST_SKIP() << "corpus not found";
  const ReadResult a = read_obj(path);
  ASSERT_TRUE(a.ok()) << a.error;
  TempDir dir;
  WriteOptions o;
  o.ply_encoding = GetParam();
  ASSERT_TRUE(write_mesh(a.mesh, dir / "duck.ply", o).ok());
  const ReadResult b = read_mesh(dir / "duck.ply");
  ASSERT_TRUE(b.ok()) << b.error;
  EXPECT_EQ(b.mesh.face_offsets, a.mesh.face_offsets);
  EXPECT_EQ(b.mesh.corner_vertex, a.mesh.corner_vertex);
  for (Index v = 0; v < a.mesh.num_vertices(); ++v)
    ASSERT_TRUE(float_equal(a.mesh.positions[v], b.mesh.positions[v])) << "vertex " << v;
  for (Index c = 0; c < a.mesh.num_corners(); ++c)
    ASSERT_TRUE(float_equal(a.mesh.uv_sets[0].values[a.mesh.uv_sets[0].corner[c]], b.mesh.uv_sets[0].values[b.mesh.uv_sets[0].corner[c]])) << "corner " << c;
}

TEST_P(PlyRoundTrip, SeveralUvSetsSurvive) {
  PolyMesh m = quad_grid(3, 2);
  UvSet& second = m.uv_sets.emplace_back();
  second.name = "texcoord1";
  for (Index c = 0; c < m.num_corners(); ++c) {
    second.corner.push_back(c % 5 == 0 ? kInvalidIndex : static_cast<Index>(second.values.size()));
    if (c % 5 != 0) second.values.emplace_back(0.25 * (c % 4), 0.5 * (c % 3));
  }
  TempDir dir;
  WriteOptions o;
  o.ply_encoding = GetParam();
  ASSERT_TRUE(write_mesh(m, dir / "two.ply", o).ok());
  const ReadResult r = read_mesh(dir / "two.ply");
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.mesh.uv_sets.size(), 2u);
  EXPECT_EQ(r.mesh.uv_sets[1].name, "texcoord1");
  for (std::size_t k = 0; k < 2; ++k)
    for (Index c = 0; c < m.num_corners(); ++c) {
      const Index ta = m.uv_sets[k].corner[c], tb = r.mesh.uv_sets[k].corner[c];
      ASSERT_EQ(ta == kInvalidIndex, tb == kInvalidIndex) << "set " << k << " corner " << c;
      if (ta != kInvalidIndex) {
        EXPECT_TRUE(float_equal(m.uv_sets[k].values[ta], r.mesh.uv_sets[k].values[tb])) << "set " << k << " corner " << c;
      }
    }
}

TEST(ObjWrite, FurtherUvSetsAreDroppedWithAWarning) {
  PolyMesh m = quad_grid(2, 2);
  m.uv_sets.push_back(m.uv_sets[0]);
  TempDir dir;
  const WriteResult w = write_mesh(m, dir / "one.obj");
  ASSERT_TRUE(w.ok()) << w.error;
  ASSERT_EQ(w.warnings.size(), 1u);
  EXPECT_NE(w.warnings[0].find("1 further set"), std::string::npos) << w.warnings[0];
  const ReadResult r = read_mesh(dir / "one.obj");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.uv_sets.size(), 1u);
  EXPECT_EQ(r.mesh.uv_sets[0].corner, m.uv_sets[0].corner);
}

// A face without a material (group, object) after one with: OBJ has no "none", usemtl holds until
// the next one, so the writer ends the tag with Blender's `usemtl (null)` and the reader reads
// "(null)" back as no tag. Without it the last face came back red.
TEST(ObjWrite, FaceWithoutTagAfterATaggedFaceEndsTheTag) {
  const ReadResult r = obj(std::string(kSquareVerts) +
                           "f 1 2 3\no A\ng G\nusemtl red\nf 1 3 4\no (null)\ng (null)\nusemtl (null)\nf 2 3 4\n");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.face_material, (std::vector<Index>{X, 0, X}));
  EXPECT_EQ(r.mesh.face_group, (std::vector<Index>{X, 0, X}));
  EXPECT_EQ(r.mesh.face_object, (std::vector<Index>{X, 0, X}));
  EXPECT_EQ(r.mesh.material_names, (std::vector<std::string>{"red"}));
  std::string out, error;
  ASSERT_TRUE(io_detail::format_obj(r.mesh, {}, out, error)) << error;
  EXPECT_NE(out.find("f 1 2 3\no A\ng G\nusemtl red\nf 1 3 4\no (null)\ng (null)\nusemtl (null)\nf 2 3 4\n"),
            std::string::npos)
      << out;
  const ReadResult back = obj(out);
  ASSERT_TRUE(back.ok()) << back.error;
  EXPECT_EQ(mesh_difference(r.mesh, back.mesh), "");
}

// PLY and OFF have no per-face tags: writing them warns (the CLI prints warnings), one line per
// kind; OFF also drops UVs, normals and colours with a warning. Nothing to drop: no warning.
TEST(IoWrite, PlyAndOffWarnAboutWhatTheyDrop) {
  PolyMesh m = quad_grid(2, 2);
  m.material_names = {"red", "blue"};
  m.face_material = {0, 0, 1, X};
  m.face_smoothing = {0, 1, 1, 1};
  TempDir dir;
  const WriteResult ply = write_mesh(m, dir / "m.ply");
  ASSERT_TRUE(ply.ok()) << ply.error;
  ASSERT_EQ(ply.warnings.size(), 2u);
  EXPECT_NE(ply.warnings[0].find("no per-face materials (usemtl); 2 on 3 face(s) dropped"), std::string::npos)
      << ply.warnings[0];
  EXPECT_NE(ply.warnings[1].find("smoothing groups"), std::string::npos) << ply.warnings[1];
  const WriteResult off = write_mesh(m, dir / "m.off");
  ASSERT_TRUE(off.ok()) << off.error;
  ASSERT_EQ(off.warnings.size(), 3u);  // UVs, materials, smoothing groups
  EXPECT_NE(off.warnings[0].find("OFF has no texture coordinates; 1 UV set(s) dropped"), std::string::npos)
      << off.warnings[0];
  PolyMesh bare = quad_grid(2, 2);
  bare.uv_sets.clear();
  EXPECT_TRUE(write_mesh(bare, dir / "b.ply").warnings.empty());
  EXPECT_TRUE(write_mesh(bare, dir / "b.off").warnings.empty());
}

INSTANTIATE_TEST_SUITE_P(Encodings, PlyRoundTrip,
                         ::testing::Values(PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian,
                                           PlyEncoding::BinaryBigEndian),
                         [](const auto& info) { return encoding_name(info.param); });

TEST(PlyRead, AsciiWithAliasesExtraElementsAndPerVertexAttributes) {
  const std::string text =
      "ply\r\n"
      "format ascii 1.0\r\n"
      "comment made by hand\r\n"
      "obj_info nothing\r\n"
      "element material 1\r\n"
      "property uint8 ambient\r\n"
      "property list uchar int32 junk\r\n"
      "element vertex 4\r\n"
      "property float32 x\r\nproperty float32 y\r\nproperty double z\r\n"
      "property list uchar float extra\r\n"
      "property float nx\r\nproperty float ny\r\nproperty float nz\r\n"
      "property float s\r\nproperty float t\r\n"
      "property uchar red\r\nproperty uchar green\r\nproperty uchar blue\r\nproperty uchar alpha\r\n"
      "element face 2\r\n"
      "property uchar flags\r\n"
      "property list uint8 uint32 vertex_index\r\n"
      "element edge 1\r\n"
      "property int vertex1\r\nproperty int vertex2\r\n"
      "end_header\r\n"
      "7 3 1 2 3\r\n"
      "0 0 0 0 0 0 1 0 0 255 0 0 255\r\n"
      "1 0 0 2 9 9 0 0 1 1 0 0 255 0 255\r\n"
      "1 1 0 0 0 0 1 1 1 0 0 255 255\r\n"
      "0 1 0 0 0 0 1 0 1 51 51 51 255\r\n"
      "0 4 0 1 2 3\r\n"
      "1 3 0 2 3\r\n"
      "0 1\r\n";
  const ReadResult r = io_detail::parse_ply(text, "h.ply");
  ASSERT_TRUE(r.ok()) << r.error;
  const PolyMesh& m = r.mesh;
  EXPECT_EQ(m.positions, (std::vector<Vec3>{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)}));
  EXPECT_EQ(m.face_offsets, (std::vector<Index>{0, 4, 7}));
  EXPECT_EQ(m.corner_vertex, (std::vector<Index>{0, 1, 2, 3, 0, 2, 3}));
  EXPECT_EQ(m.uv_sets[0].corner, m.corner_vertex);      // per-vertex UVs, indexed by vertex
  EXPECT_EQ(m.corner_normal, m.corner_vertex);
  EXPECT_EQ(m.uv_sets[0].values[2], Vec2(1, 1));
  EXPECT_EQ(m.vertex_colors[1], Vec3(0, 1, 0));
  EXPECT_EQ(m.vertex_colors[3], Vec3(0.2, 0.2, 0.2));
}

namespace {

// Hand-assembled big-endian binary PLY: doubles, ushort list counts, uint indices, a list on
// the vertex element and an element after the faces.
std::string big_endian_ply() {
  std::string s =
      "ply\nformat binary_big_endian 1.0\n"
      "element vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
      "property list uchar short ids\n"
      "element face 1\nproperty list ushort uint vertex_indices\nproperty list uchar float texcoord\n"
      "element tail 2\nproperty list int char bytes\n"
      "end_header\n";
  const auto put = [&](auto v) {
    char b[sizeof v];
    std::memcpy(b, &v, sizeof v);
    if constexpr (std::endian::native == std::endian::little) std::reverse(b, b + sizeof v);
    s.append(b, sizeof v);
  };
  const double xyz[3][3] = {{0, 0, 0}, {1.25, 0, 0}, {0, -3.5, 1e10}};
  for (const auto& p : xyz) {
    put(p[0]), put(p[1]), put(p[2]);
    put(std::uint8_t{2}), put(std::int16_t{-1}), put(std::int16_t{7});
  }
  put(std::uint16_t{3}), put(std::uint32_t{2}), put(std::uint32_t{0}), put(std::uint32_t{1});
  put(std::uint8_t{6});
  for (float f : {0.5f, 0.25f, 0.0f, 0.0f, 1.0f, 0.0f}) put(f);
  put(std::int32_t{1}), put(std::int8_t{5});
  put(std::int32_t{0});
  return s;
}

}  // namespace

TEST(PlyRead, BinaryBigEndianWithDoublesAndSkippedLists) {
  const ReadResult r = io_detail::parse_ply(big_endian_ply(), "be.ply");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.positions[2], Vec3(0, -3.5, 1e10));
  EXPECT_EQ(r.mesh.corner_vertex, (std::vector<Index>{2, 0, 1}));
  EXPECT_EQ(r.mesh.uv_sets[0].corner, (std::vector<Index>{0, 1, 2}));
  EXPECT_EQ(r.mesh.uv_sets[0].values[0], Vec2(0.5, 0.25));
  EXPECT_EQ(r.mesh.uv_sets[0].values[2], Vec2(1, 0));
}

TEST(PlyRead, FacesBeforeVerticesAndTexcoordBeforeIndices) {
  const std::string text =
      "ply\nformat ascii 1.0\n"
      "element face 1\nproperty list uchar float texcoord\nproperty list uchar int vertex_indices\n"
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "end_header\n"
      "6 0 0 1 0 0 1 3 0 1 2\n"
      "0 0 0\n1 0 0\n0 1 0\n";
  const ReadResult r = io_detail::parse_ply(text, "o.ply");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.corner_vertex, (std::vector<Index>{0, 1, 2}));
  EXPECT_EQ(r.mesh.uv_sets[0].values[1], Vec2(1, 0));
}

TEST(PlyWrite, PerCornerNormalsThatDisagreeAreNotWritten) {
  PolyMesh m = quad_grid(2, 1);
  m.normals = {Vec3(0, 0, 1), Vec3(0, 0, -1)};
  m.corner_normal.assign(m.num_corners(), 0);
  m.corner_normal[4] = 1;  // vertex 1 in face 1 disagrees with face 0
  std::string out, error;
  ASSERT_TRUE(io_detail::format_ply(m, {}, out, error)) << error;
  EXPECT_EQ(out.find("property float nx"), std::string::npos);
  m.corner_normal[4] = 0;
  ASSERT_TRUE(io_detail::format_ply(m, {}, out, error)) << error;
  EXPECT_NE(out.find("property float nx"), std::string::npos);
}

// --- OFF --------------------------------------------------------------------------------------

TEST(OffRead, CommentsVariantsAndFaceColours) {
  const ReadResult r = io_detail::parse_off(
      "# a comment\nCOFF 4 2 0 # counts on the header line\n"
      "\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n1 1 0 0 0 255 255\n0 1 0 9 9 9 255\n"
      "4 0 1 2 3 255 0 0\n3 0 2 3\n",
      "c.off");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.face_offsets, (std::vector<Index>{0, 4, 7}));
  EXPECT_EQ(r.mesh.corner_vertex, (std::vector<Index>{0, 1, 2, 3, 0, 2, 3}));
  EXPECT_EQ(r.mesh.positions[2], Vec3(1, 1, 0));

  const ReadResult n = io_detail::parse_off("NOFF\r\n3 1 3\r\n0 0 0 0 0 1\r\n1 0 0 0 0 1\r\n0 1 0 0 0 1\r\n3 0 1 2\r\n", "n.off");
  ASSERT_TRUE(n.ok()) << n.error;
  EXPECT_EQ(n.mesh.positions[1], Vec3(1, 0, 0));

  const ReadResult h = io_detail::parse_off("4OFF\n3 1 0\n0 0 0 1\n2 0 0 2\n0 4 0 2\n3 0 1 2\n", "h.off");
  ASSERT_TRUE(h.ok()) << h.error;
  EXPECT_EQ(h.mesh.positions[2], Vec3(0, 2, 0));
}

TEST(OffRoundTrip, ExactWithSeventeenDigits) {
  PolyMesh m = quad_grid(4, 3);
  m.positions[5] = Vec3(1.0 / 3.0, -2.0 / 7.0, 1e-300);
  m.uv_sets.clear();
  m.add_face({0, 6, 12, 7, 1});
  TempDir dir;
  WriteOptions o;
  o.precision = 17;
  ASSERT_TRUE(write_mesh(m, dir / "g.off", o).ok());
  const ReadResult r = read_mesh(dir / "g.off");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(mesh_difference(m, r.mesh), "");
}

// --- dispatch and atomic writes ---------------------------------------------------------------

TEST(IoDispatch, FormatFromExtensionIgnoresCase) {
  MeshFormat f{};
  EXPECT_TRUE(format_from_path("a/b.OBJ", f));
  EXPECT_EQ(f, MeshFormat::Obj);
  EXPECT_TRUE(format_from_path("x.Ply", f));
  EXPECT_EQ(f, MeshFormat::Ply);
  EXPECT_TRUE(format_from_path("x.off", f));
  EXPECT_EQ(f, MeshFormat::Off);
  EXPECT_FALSE(format_from_path("x.stl", f));
  EXPECT_FALSE(format_from_path("obj", f));
}

TEST(IoDispatch, UnknownExtensionIsAnErrorNamingThePath) {
  TempDir dir;
  const ReadResult r = read_mesh(dir / "mesh.stl");
  EXPECT_NE(r.error.find("mesh.stl"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("unknown mesh format"), std::string::npos) << r.error;
  const WriteResult w = write_mesh(quad_grid(1, 1), dir / "mesh.xyz");
  EXPECT_NE(w.error.find("mesh.xyz"), std::string::npos) << w.error;
  EXPECT_TRUE(dir.entries().empty());
}

TEST(IoAtomicWrite, ReplacesTheTargetAndLeavesNoTemporaryFile) {
  TempDir dir;
  ASSERT_TRUE(write_file_atomically(dir / "r.json", "old").ok());
  ASSERT_TRUE(write_file_atomically(dir / "r.json", "new contents").ok());
  EXPECT_EQ(read_bytes(dir / "r.json"), "new contents");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"r.json"}));
  ASSERT_TRUE(write_file_atomically(dir / "empty.txt", "").ok());
  EXPECT_EQ(fs::file_size(dir / "empty.txt"), 0u);
}

TEST(IoAtomicWrite, TargetThatIsADirectoryFailsCleanly) {
  TempDir dir;
  fs::create_directory(dir / "d.obj");
  const WriteResult w = write_mesh(quad_grid(1, 1), dir / "d.obj");
  EXPECT_NE(w.error.find("d.obj"), std::string::npos) << w.error;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"d.obj"}));
  EXPECT_TRUE(fs::is_empty(dir / "d.obj"));
}

TEST(IoAtomicWrite, ParentThatIsAFileFailsCleanly) {
  TempDir dir;
  write_bytes(dir / "file", "x");
  const WriteResult w = write_file_atomically(dir / "file" / "x.obj", "data");
  EXPECT_NE(w.error.find("not a directory"), std::string::npos) << w.error;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"file"}));
}

TEST(IoRoundTrip, EveryFormatAgreesOnAGrid) {
  const PolyMesh m = quad_grid(40, 30);
  TempDir dir;
  for (const char* name : {"g.obj", "g.off", "g.ply"}) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(write_mesh(m, dir / name).ok());
    const ReadResult r = read_mesh(dir / name);
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.mesh.face_offsets, m.face_offsets);
    EXPECT_EQ(r.mesh.corner_vertex, m.corner_vertex);
    for (Index v = 0; v < m.num_vertices(); ++v)
      ASSERT_TRUE(float_equal(m.positions[v], r.mesh.positions[v].cast<float>())) << "vertex " << v;
  }
}

// --- number parsing -----------------------------------------------------------------------------

TEST(IoNumbers, FastDecimalPathAgreesWithFromCharsBitForBit) {
  // Oracle: std::from_chars (correctly rounded). The fast path must give the same double for
  // every decimal it accepts and must accept and reject the same texts.
  std::mt19937_64 rng(99);
  const auto digit = [&] { return static_cast<char>('0' + rng() % 10); };
  int compared = 0;
  for (int i = 0; i < 300000; ++i) {
    std::string s;
    if (rng() % 2) s += '-';
    const int int_digits = static_cast<int>(rng() % 12), frac_digits = static_cast<int>(rng() % 14);
    for (int k = 0; k < int_digits; ++k) s += digit();
    if (rng() % 4 != 0) {
      s += '.';
      for (int k = 0; k < frac_digits; ++k) s += digit();
    }
    if (rng() % 5 == 0) {
      s += rng() % 2 ? 'e' : 'E';
      if (rng() % 2) s += rng() % 2 ? '-' : '+';
      for (int k = 0, n = static_cast<int>(rng() % 4); k < n; ++k) s += digit();
    }
    double expected = 0.0, actual = 0.0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), expected);
    const bool expected_ok = ec == std::errc() && ptr == s.data() + s.size();
    const char* next = nullptr;
    const bool ok = io_detail::parse_double_token(s.data(), s.data() + s.size(), actual, next);
    ASSERT_EQ(ok, expected_ok) << s;
    if (ok) {
      ASSERT_EQ(std::bit_cast<std::uint64_t>(actual), std::bit_cast<std::uint64_t>(expected)) << s;
      ++compared;
    }
  }
  EXPECT_GT(compared, 200000);
  double v = 0.0;
  const char* next = nullptr;
  for (const char* bad : {"", "-", ".", "+-1", "1e", "1x", "--1", "0x1p3"}) {
    const std::string_view t(bad);
    EXPECT_FALSE(io_detail::parse_double_token(t.data(), t.data() + t.size(), v, next)) << bad;
  }
  const std::string_view plus("+2.5 ");
  ASSERT_TRUE(io_detail::parse_double_token(plus.data(), plus.data() + plus.size(), v, next));
  EXPECT_EQ(v, 2.5);
  EXPECT_EQ(*next, ' ');
}

// A mesh large enough that its lines are formatted in chunks on several threads (io/obj.cpp):
// the text reads back as the same mesh, and a name statement appears only where a face's tag
// differs from the face before it — none repeated or lost where a chunk begins.
TEST(IoWrite, ChunkedObjTextIsTheSameMeshWithOneStatementPerTagChange) {
  PolyMesh m = quad_grid(400, 300);  // 120 000 faces, 120 701 vertices and UVs
  ASSERT_GT(m.num_faces(), 100000);
  // Whole numbers and binary fractions: they read back exactly at the default precision.
  for (Vec3& p : m.positions) p = (p * 1200.0).array().round().matrix();
  for (Vec2& t : m.uv_sets[0].values) t = (t * 64.0).array().round().matrix() / 64.0;
  m.material_names = {"red", "blue", "green"};
  m.group_names = {"a", "b"};
  const Index nf = m.num_faces();
  m.face_material.resize(nf);
  m.face_group.resize(nf);
  m.face_smoothing.resize(nf);
  std::size_t material_changes = 0, group_changes = 0, smoothing_changes = 0;
  for (Index f = 0; f < nf; ++f) {
    // Runs of unequal lengths (untagged leading faces included), so chunk starts fall anywhere.
    m.face_material[f] = f < 5 ? X : Index((f / 37) % 3);
    m.face_group[f] = Index((f / 1009) % 2);
    m.face_smoothing[f] = (f / 53) % 2;
    if (m.face_material[f] != (f == 0 ? X : m.face_material[f - 1])) ++material_changes;
    if (m.face_group[f] != (f == 0 ? X : m.face_group[f - 1])) ++group_changes;
    if (f == 0 || m.face_smoothing[f] != m.face_smoothing[f - 1]) ++smoothing_changes;
  }
  const std::string text = io_test::obj_bytes(m, "chunked");
  auto count_lines = [&](const std::string& prefix) {
    std::size_t n = 0;
    for (std::size_t at = 0; at < text.size();) {
      const std::size_t end = text.find('\n', at);
      if (text.compare(at, prefix.size(), prefix) == 0) ++n;
      at = end == std::string::npos ? text.size() : end + 1;
    }
    return n;
  };
  EXPECT_EQ(count_lines("usemtl "), material_changes);
  EXPECT_EQ(count_lines("g "), group_changes);
  EXPECT_EQ(count_lines("s "), smoothing_changes);
  EXPECT_EQ(count_lines("v "), std::size_t(m.num_vertices()));
  EXPECT_EQ(count_lines("vt "), m.uv_sets[0].values.size());
  EXPECT_EQ(count_lines("f "), std::size_t(nf));
  const ReadResult back = obj(text);
  ASSERT_TRUE(back.ok()) << back.error;
  EXPECT_EQ(mesh_difference(m, back.mesh), "");
}
