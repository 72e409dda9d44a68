// quadlod Python module — conversion between NumPy arrays and PolyMesh (issue 22).
//
// A mesh crosses the Python boundary as flat arrays, the way Blender and trimesh hold polygons:
//   vertices    (V, 3) float32 / float64
//   faces       either (F, k) integers (every face has k corners) or a pair
//               (corner_vertices (C,), face_sizes (F,)) — Blender's loops[].vertex_index and
//               polygons[].loop_total;
//   uvs         optional, per corner (C, 2) floats, or a dict {layer name: (C, 2)}; NaN = no UV;
//   normals     optional, per corner (C, 3) floats (Blender's custom split normals);
//   materials   optional, per face (F,) integers >= 0 (Blender's material_index).
// Each input array is read once, straight into the PolyMesh (the one conversion); lists and
// arrays of other dtypes are converted by NumPy first. Per-corner values become one pool entry
// per corner: the core compares UVs and normals by value (src/mesh/features.h), so no welding
// is needed for seams to be found.
#pragma once

#include "quadlod/mesh.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

namespace quadlod::python {

namespace py = pybind11;

/// Raised for every bad input and every failed run; the message is the one the CLI prints
/// after "quadlod: " (the library's error text).
struct MeshInputError {
  std::string message;
};

/// Builds a PolyMesh from the arrays above (any of uvs / normals / materials may be None).
/// Throws MeshInputError naming the array and element ("faces: corner 7 refers to vertex 12 but
/// only 10 vertices are given").
PolyMesh mesh_from_arrays(const py::handle& vertices, const py::handle& faces, const py::handle& uvs,
                          const py::handle& normals, const py::handle& materials);

/// Blend shapes (issue 34): `morph_targets` is None or a dict {shape name: (V, 3) displacements,
/// one row per vertex} (Blender: shape key co − basis co); they go into mesh.morph_targets in the
/// dict's order. Throws MeshInputError naming the shape on a wrong shape or a non-finite value.
void read_morph_targets(PolyMesh& mesh, const py::handle& morph_targets);

/// The same from a dict with the keys "vertices", "faces" (and optionally "face_sizes", "uvs",
/// "normals", "materials") — what simplify() returns — or a tuple (vertices, faces).
PolyMesh mesh_from_object(const py::handle& mesh);

/// The mesh as a dict of NumPy arrays: "vertices" (V,3) float64, "faces" (C,) int32 corner
/// vertices, "face_sizes" (F,) int32, and when present "uvs" (per corner (C,2), NaN where a corner
/// has none; a dict by layer name when `uvs_as_dict`), "normals" (C,3), "materials" (F,) int32
/// (-1 = none), "morph_targets" ({name: (V,3) float64 displacements}, issue 34).
py::dict mesh_to_dict(const PolyMesh& mesh, bool uvs_as_dict);

}  // namespace quadlod::python
