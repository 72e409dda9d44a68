// Derived connectivity of a PolyMesh: undirected edges, edge→corner and vertex→corner incidence,
// boundary loops, connected components, and the opposite edge of every quad edge.
//
// Terminology (corners are the "half-edges" of this kernel):
//   corner c of face f sits at vertex corner_vertex[c]; its *edge* runs from that vertex to the
//   vertex of the next corner of f. So a face of k corners has k edges, one per corner, and an
//   undirected edge is shared by the corners of all faces that use it:
//     1 corner  → boundary edge,   2 corners → manifold interior edge,   >2 → non-manifold edge.
//
//         v3 ──────── v2          quad corners c0..c3 at v0..v3:
//          │   c3  c2 │             edge(c0) = v0→v1 is opposite edge(c2) = v2→v3
//          │          │             edge(c1) = v1→v2 is opposite edge(c3) = v3→v0
//          │   c0  c1 │           (paper §3.1: "opposing quad edges" of a poly-chord)
//         v0 ──────── v1
//
// Building is linear in the number of corners (a bucket per smaller endpoint, no global sort).
// Nothing here is cached in the mesh: rebuild after editing the mesh.
#pragma once

#include "quadlod/mesh.h"

#include <array>
#include <span>
#include <vector>

namespace quadlod {

struct BoundaryLoop {
  std::vector<Index> corners;  ///< boundary corners in walking order; edge(corner) is on the loop
};

struct Connectivity {
  Index num_vertices = 0;
  Index num_faces = 0;
  Index num_edges = 0;

  std::vector<Index> corner_vertex;                ///< vertex of each corner (copy of the mesh's)
  std::vector<Index> corner_face;                  ///< face of each corner
  std::vector<Index> corner_next;                  ///< next corner in the same face
  std::vector<Index> corner_prev;                  ///< previous corner in the same face
  std::vector<Index> corner_edge;                  ///< undirected edge of each corner's edge
  std::vector<std::array<Index, 2>> edge_vertices;  ///< endpoints, smaller id first

  /// CSR edge → corners using the edge (in increasing corner order).
  std::vector<Index> edge_corner_offsets;
  std::vector<Index> edge_corners;

  /// CSR vertex → corners sitting at the vertex (in increasing corner order).
  std::vector<Index> vertex_corner_offsets;
  std::vector<Index> vertex_corners;

  /// Degree (number of corners) of each face, copied for cheap access.
  std::vector<Index> face_degree;

  // --- queries ---------------------------------------------------------------------------------
  std::span<const Index> corners_of_edge(Index e) const {
    return {edge_corners.data() + edge_corner_offsets[e],
            edge_corner_offsets[e + 1] - edge_corner_offsets[e]};
  }
  std::span<const Index> corners_at_vertex(Index v) const {
    return {vertex_corners.data() + vertex_corner_offsets[v],
            vertex_corner_offsets[v + 1] - vertex_corner_offsets[v]};
  }
  Index edge_face_count(Index e) const { return edge_corner_offsets[e + 1] - edge_corner_offsets[e]; }
  bool is_boundary_edge(Index e) const { return edge_face_count(e) == 1; }
  bool is_nonmanifold_edge(Index e) const { return edge_face_count(e) > 2; }
  bool is_quad(Index f) const { return face_degree[f] == 4; }

  /// The corner on the other side of corner c's edge, when that edge is a manifold interior edge
  /// (exactly two corners); kInvalidIndex on boundary and non-manifold edges.
  Index across(Index c) const {
    const Index e = corner_edge[c];
    if (edge_face_count(e) != 2) return kInvalidIndex;
    const Index first = edge_corners[edge_corner_offsets[e]];
    return first == c ? edge_corners[edge_corner_offsets[e] + 1] : first;
  }

  /// For a corner of a quad: the corner two steps on, whose edge is the opposite side of the
  /// quad. kInvalidIndex when the face is not a quad.
  Index opposite_corner_in_quad(Index c) const {
    return face_degree[corner_face[c]] == 4 ? corner_next[corner_next[c]] : kInvalidIndex;
  }

  /// The vertex where corner c's edge ends (the vertex of the next corner).
  Index tip_vertex(Index c) const { return corner_vertex[corner_next[c]]; }

  /// The other endpoint of edge e.
  Index other_vertex(Index e, Index v) const {
    return edge_vertices[e][0] == v ? edge_vertices[e][1] : edge_vertices[e][0];
  }
};

/// Builds the connectivity of `mesh` (which must satisfy PolyMesh::check_layout()).
/// Faces that use a vertex twice are tolerated: their degenerate edges become ordinary edges
/// whose two endpoints may coincide.
Connectivity build_connectivity(const PolyMesh& mesh);

/// Boundary loops: boundary corners chained tip to tail. At a vertex with several outgoing
/// boundary edges (a "bow-tie" vertex) the walk stays in the fan it came through, so each loop is
/// a simple cycle; where the fan cannot be walked (non-manifold edges) it takes the lowest unused
/// outgoing boundary corner. Every boundary corner belongs to exactly one loop.
std::vector<BoundaryLoop> boundary_loops(const Connectivity& conn);

/// Connected components of faces joined through shared edges (any number of faces per edge;
/// faces meeting only at a vertex are separate components, as in shared/corpus/stats.py).
struct FaceComponents {
  Index count = 0;
  std::vector<Index> face_component;  ///< component id of each face, ids dense from 0
};
FaceComponents face_components(const Connectivity& conn);

/// Vertices whose incident faces do not form one edge-connected fan (a bow-tie, or vertices of
/// non-manifold edges). Returns one flag per vertex.
std::vector<bool> nonmanifold_vertices(const Connectivity& conn);

}  // namespace quadlod
