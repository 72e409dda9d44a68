// Mesh reader/writer throughput: a generated 1000×1000-quad grid with UVs (1M faces, written
// once to the temp directory, never committed) and the two largest corpus files.
//
//   cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release -DQUADLOD_BUILD_BENCH=ON
//   cmake --build build-bench -j2 --target quadlod_bench
//   build-bench/quadlod_bench --benchmark_filter='Obj|Ply'
#include "io/io_common.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

namespace fs = std::filesystem;
using namespace quadlod;

namespace {

constexpr Index kGrid = 1000;

// n × n quads, (n+1)² vertices and UVs, "f a/a b/b c/c d/d" faces: the shape of a typical
// artist OBJ at 1M faces (about 60 MB).
PolyMesh make_grid(Index n) {
  PolyMesh m;
  m.positions.reserve((n + 1) * (n + 1));
  UvSet& uv = m.uv_sets.emplace_back();
  uv.values.reserve((n + 1) * (n + 1));
  for (Index j = 0; j <= n; ++j)
    for (Index i = 0; i <= n; ++i) {
      m.positions.emplace_back(0.001 * i + 0.5, 0.25 * std::sin(0.01 * i) - 0.3, 0.001 * j - 1.25);
      uv.values.emplace_back(double(i) / n, double(j) / n);
    }
  m.face_offsets.reserve(std::size_t{n} * n + 1);
  m.corner_vertex.reserve(4ull * n * n);
  for (Index j = 0; j < n; ++j)
    for (Index i = 0; i < n; ++i) {
      const Index a = j * (n + 1) + i;
      for (const Index v : {a, a + 1, a + n + 2, a + n + 1}) m.corner_vertex.push_back(v);
      m.face_offsets.push_back(m.num_corners());
    }
  uv.corner = m.corner_vertex;
  return m;
}

// Writes the grid in `ext` format once per process (and reuses a file left by an earlier run).
const fs::path& grid_file(const char* ext, PlyEncoding encoding = PlyEncoding::BinaryLittleEndian) {
  static std::map<std::string, fs::path> files;
  const std::string key = std::string(ext) + std::to_string(static_cast<int>(encoding));
  auto it = files.find(key);
  if (it != files.end()) return it->second;
  const fs::path path = fs::temp_directory_path() /
                        ("quadlod-bench-grid-" + std::to_string(kGrid) + "-" + key + "." + ext);
  if (!fs::exists(path)) {
    WriteOptions o;
    o.ply_encoding = encoding;
    const WriteResult w = write_mesh(make_grid(kGrid), path, o);
    if (!w.ok()) std::fprintf(stderr, "%s\n", w.error.c_str());
  }
  return files.emplace(key, path).first->second;
}

fs::path corpus(const char* name) {
  return fs::path(__FILE__).parent_path() / "../../../shared/corpus" / name;
}

void read_file_benchmark(benchmark::State& state, const fs::path& path) {
  if (!fs::exists(path)) {
    state.SkipWithError(("missing " + path.string()).c_str());
    return;
  }
  Index faces = 0;
  for (auto _ : state) {
    const ReadResult r = read_mesh(path);
    if (!r.ok()) {
      state.SkipWithError(r.error.c_str());
      return;
    }
    faces = r.mesh.num_faces();
    benchmark::DoNotOptimize(r.mesh.positions.data());
  }
  state.counters["faces"] = faces;
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * fs::file_size(path)));
}

void BM_ReadObjGrid1M(benchmark::State& state) { read_file_benchmark(state, grid_file("obj")); }
void BM_ReadPlyBinaryGrid1M(benchmark::State& state) { read_file_benchmark(state, grid_file("ply")); }
void BM_ReadPlyAsciiGrid1M(benchmark::State& state) {
  read_file_benchmark(state, grid_file("ply", PlyEncoding::Ascii));
}
void BM_ReadOffGrid1M(benchmark::State& state) { read_file_benchmark(state, grid_file("off")); }
void BM_ReadObjSuzanneSubdiv(benchmark::State& state) {
  read_file_benchmark(state, corpus("assimp_suzanne_subdiv.obj"));
}
void BM_ReadObjCruiser(benchmark::State& state) {
  read_file_benchmark(state, corpus("flightgear_cg57_cruiser_hd.obj"));
}

void BM_FormatObjGrid1M(benchmark::State& state) {
  const PolyMesh m = make_grid(kGrid);
  std::string out, error;
  for (auto _ : state) {
    io_detail::format_obj(m, {}, out, error);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * out.size()));
}

}  // namespace

BENCHMARK(BM_ReadObjGrid1M)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_ReadPlyBinaryGrid1M)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_ReadPlyAsciiGrid1M)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_ReadOffGrid1M)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_ReadObjSuzanneSubdiv)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadObjCruiser)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FormatObjGrid1M)->Unit(benchmark::kMillisecond)->MinTime(2.0);
