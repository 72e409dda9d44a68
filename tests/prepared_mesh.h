// A mesh with its connectivity and analysis (the inputs of the selection stage), for the tests
// of src/select/.
#pragma once

#include "mesh/connectivity.h"
#include "quadlod/mesh.h"
#include "topology/analysis.h"

#include <utility>

namespace quadlod::select_test {

struct Prepared {
  PolyMesh mesh;
  Connectivity conn;
  AnalysisResult analysis;
};

inline Prepared prepare(PolyMesh mesh, const AnalysisParams& ap = {}) {
  Prepared p{std::move(mesh), {}, {}};
  p.conn = build_connectivity(p.mesh);
  p.analysis = analyze(p.mesh, p.conn, ap);
  return p;
}

}  // namespace quadlod::select_test
