// Micro-benchmarks of collapse_clusters (src/post/cluster_collapse.h) on ~100k-face generated
// meshes. Build with -DQUADLOD_BUILD_BENCH=ON; run `quadlod_bench --benchmark_filter=Collapse`.
//   * GridBlocks: make_grid(316, 316), every other row and column chord collapsed (2×2 blocks
//     → 1 vertex, 75% fewer faces, nothing refused: one round);
//   * TorusRings: make_torus(400, 250), every other ring chord collapsed (50% fewer faces);
//   * VaseRandom: make_demo_vase(320, 320), 30% of all edges collapsed at random (pathological:
//     thousands of refusals, ~11 rounds).
// Connectivity is built once outside the timed loop (it is the previous stage's output).
#include "mesh/connectivity.h"
#include "post/cluster_collapse.h"
#include "quadlod/generators.h"

#include <benchmark/benchmark.h>

#include <random>

namespace {

using namespace quadlod;

void run(benchmark::State& state, const PolyMesh& mesh, const Connectivity& conn,
         const std::vector<std::uint8_t>& kept) {
  for (auto _ : state) {
    ClusterCollapseResult r = collapse_clusters(mesh, conn, kept);
    benchmark::DoNotOptimize(r.mesh.corner_vertex.data());
    state.counters["faces_out"] = r.stats.faces_out;
    state.counters["refusals"] = r.stats.total_refusals();
    state.counters["rounds"] = r.stats.rounds;
  }
  state.counters["faces_in"] = mesh.num_faces();
}

void BM_CollapseGridBlocks(benchmark::State& state) {
  const Index n = 316;
  const PolyMesh mesh = make_grid(n, n);
  const Connectivity conn = build_connectivity(mesh);
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto [a, b] = conn.edge_vertices[e];
    const Index ia = a % (n + 1), ja = a / (n + 1), ib = b % (n + 1), jb = b / (n + 1);
    if ((ja == jb && std::min(ia, ib) % 2 == 0) || (ia == ib && std::min(ja, jb) % 2 == 0)) kept[e] = 0;
  }
  run(state, mesh, conn, kept);
}
BENCHMARK(BM_CollapseGridBlocks)->Unit(benchmark::kMillisecond);

void BM_CollapseTorusRings(benchmark::State& state) {
  const Index n = 400, m = 250;
  const PolyMesh mesh = make_torus(n, m);
  const Connectivity conn = build_connectivity(mesh);
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto [a, b] = conn.edge_vertices[e];
    const Index ia = a / m, ib = b / m;
    if (ia != ib && std::max(ia, ib) - std::min(ia, ib) == 1 && std::min(ia, ib) % 2 == 0) kept[e] = 0;
  }
  run(state, mesh, conn, kept);
}
BENCHMARK(BM_CollapseTorusRings)->Unit(benchmark::kMillisecond);

void BM_CollapseVaseRandom(benchmark::State& state) {
  const PolyMesh mesh = make_demo_vase(320, 320);
  const Connectivity conn = build_connectivity(mesh);
  std::mt19937_64 g(3);
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  for (auto& k : kept) k = (static_cast<double>(g() >> 11) * 0x1.0p-53) < 0.3 ? 0 : 1;
  run(state, mesh, conn, kept);
}
BENCHMARK(BM_CollapseVaseRandom)->Unit(benchmark::kMillisecond);

}  // namespace
