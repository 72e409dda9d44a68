// NumPy arrays ⇄ PolyMesh for the Python module (see mesh_arrays.h for the layout).
#include "mesh_arrays.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>

namespace quadlod::python {

namespace {

/// A NumPy array of numbers read element by element through its strides, whatever its dtype:
/// Blender fills float32 / int32 buffers, trimesh int64 / float64; none of them is copied.
class NumberArray {
 public:
  NumberArray(const py::handle& object, const std::string& name) : name_(name) {
    array_ = py::array::ensure(object);
    if (!array_) throw MeshInputError{name + ": not an array of numbers"};
    kind_ = array_.dtype().kind();
    itemsize_ = array_.itemsize();
    const bool known = (kind_ == 'f' && (itemsize_ == 4 || itemsize_ == 8)) ||
                       ((kind_ == 'i' || kind_ == 'u') &&
                        (itemsize_ == 1 || itemsize_ == 2 || itemsize_ == 4 || itemsize_ == 8));
    if (!known) {
      // Anything else (bool, object, float16, …) is converted once by NumPy.
      array_ = py::array_t<double, py::array::forcecast>::ensure(object);
      if (!array_) throw MeshInputError{name + ": not an array of numbers"};
      kind_ = 'f';
      itemsize_ = 8;
    }
  }

  const std::string& name() const { return name_; }
  py::ssize_t ndim() const { return array_.ndim(); }
  py::ssize_t rows() const { return array_.ndim() > 0 ? array_.shape(0) : 0; }
  py::ssize_t cols() const { return array_.ndim() > 1 ? array_.shape(1) : 1; }
  bool is_integer() const { return kind_ != 'f'; }

  /// Element (i, j) of a 2-D array or element i of a 1-D one (j = 0).
  double value(py::ssize_t i, py::ssize_t j = 0) const {
    const char* p = static_cast<const char*>(array_.data()) + i * array_.strides(0) +
                    (array_.ndim() > 1 ? j * array_.strides(1) : 0);
    if (kind_ == 'f') return itemsize_ == 4 ? double(load<float>(p)) : load<double>(p);
    if (kind_ == 'i') {
      switch (itemsize_) {
        case 1: return double(load<std::int8_t>(p));
        case 2: return double(load<std::int16_t>(p));
        case 4: return double(load<std::int32_t>(p));
        default: return double(load<std::int64_t>(p));
      }
    }
    switch (itemsize_) {
      case 1: return double(load<std::uint8_t>(p));
      case 2: return double(load<std::uint16_t>(p));
      case 4: return double(load<std::uint32_t>(p));
      default: return double(load<std::uint64_t>(p));
    }
  }

  /// Element i (1-D) or (i, j) as an index: an integer dtype, >= 0 and below 2^32 - 1.
  Index index(py::ssize_t i, py::ssize_t j, const char* what) const {
    const double v = value(i, j);
    if (!(v >= 0) || v >= double(kInvalidIndex) || v != std::floor(v))
      throw MeshInputError{name_ + ": " + what + " " + std::to_string(i) + " is " + format(v) +
                           ", not an index >= 0"};
    return static_cast<Index>(v);
  }

  void require_shape(py::ssize_t ndim, py::ssize_t cols, const std::string& shape) const {
    if (array_.ndim() != ndim || (ndim == 2 && array_.shape(1) != cols))
      throw MeshInputError{name_ + ": expected shape " + shape + ", got " + shape_text()};
  }

  std::string shape_text() const {
    std::string s = "(";
    for (py::ssize_t d = 0; d < array_.ndim(); ++d)
      s += (d ? ", " : "") + std::to_string(array_.shape(d));
    return s + (array_.ndim() == 1 ? ",)" : ")");
  }

 private:
  template <class T>
  static T load(const char* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));  // strided views need not be aligned
    return v;
  }
  static std::string format(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
  }

  std::string name_;
  py::array array_;
  char kind_ = 'f';
  py::ssize_t itemsize_ = 8;
};

bool is_none(const py::handle& h) { return !h || h.is_none(); }

void read_faces(PolyMesh& mesh, const py::handle& faces) {
  if (py::isinstance<py::tuple>(faces) || py::isinstance<py::list>(faces)) {
    const py::sequence pair = py::reinterpret_borrow<py::sequence>(faces);
    if (pair.size() != 2)
      throw MeshInputError{"faces: expected (corner_vertices, face_sizes) or an (F, k) array"};
    const NumberArray corners(pair[0], "faces");
    const NumberArray sizes(pair[1], "face_sizes");
    corners.require_shape(1, 1, "(C,)");
    sizes.require_shape(1, 1, "(F,)");
    const py::ssize_t num_faces = sizes.rows();
    mesh.face_offsets.resize(num_faces + 1);
    std::uint64_t total = 0;
    for (py::ssize_t f = 0; f < num_faces; ++f) {
      const Index k = sizes.index(f, 0, "face");
      if (k < 3) throw MeshInputError{"face_sizes: face " + std::to_string(f) + " has " + std::to_string(k) + " corners (at least 3)"};
      total += k;
      if (total >= kInvalidIndex) throw MeshInputError{"face_sizes: more than 2^32 - 1 corners"};
      mesh.face_offsets[f + 1] = static_cast<Index>(total);
    }
    if (py::ssize_t(total) != corners.rows())
      throw MeshInputError{"faces: " + std::to_string(corners.rows()) + " corner vertices but face_sizes add up to " +
                           std::to_string(total)};
    mesh.corner_vertex.resize(total);
    for (py::ssize_t c = 0; c < corners.rows(); ++c) mesh.corner_vertex[c] = corners.index(c, 0, "corner");
    return;
  }
  const NumberArray table(faces, "faces");
  if (table.ndim() != 2 || table.cols() < 3)
    throw MeshInputError{"faces: expected (corner_vertices, face_sizes) or an (F, k) array with k >= 3, got shape " +
                         table.shape_text()};
  const py::ssize_t k = table.cols();
  mesh.face_offsets.resize(table.rows() + 1);
  mesh.corner_vertex.resize(table.rows() * k);
  for (py::ssize_t f = 0; f < table.rows(); ++f) {
    mesh.face_offsets[f + 1] = static_cast<Index>((f + 1) * k);
    for (py::ssize_t j = 0; j < k; ++j) mesh.corner_vertex[f * k + j] = table.index(f, j, "face");
  }
}

/// One per-corner attribute: `dims` floats per corner, a pool entry per corner; a corner whose
/// first value is NaN has none.
template <class Value>
void read_per_corner(const py::handle& object, const std::string& name, Index num_corners, int dims,
                     std::vector<Value>& values, std::vector<Index>& corner) {
  const NumberArray a(object, name);
  a.require_shape(2, dims, "(C, " + std::to_string(dims) + ")");
  if (a.rows() != py::ssize_t(num_corners))
    throw MeshInputError{name + ": " + std::to_string(a.rows()) + " rows, but the faces have " +
                         std::to_string(num_corners) + " corners (one row per corner)"};
  values.resize(num_corners);
  corner.resize(num_corners);
  for (Index c = 0; c < num_corners; ++c) {
    for (int d = 0; d < dims; ++d) values[c][d] = a.value(c, d);
    corner[c] = std::isnan(values[c][0]) ? kInvalidIndex : c;
    if (corner[c] != kInvalidIndex)
      for (int d = 0; d < dims; ++d)
        if (!std::isfinite(values[c][d]))
          throw MeshInputError{name + ": corner " + std::to_string(c) + " has a non-finite value"};
  }
}

}  // namespace

PolyMesh mesh_from_arrays(const py::handle& vertices, const py::handle& faces, const py::handle& uvs,
                          const py::handle& normals, const py::handle& materials) {
  PolyMesh mesh;
  {
    const NumberArray v(vertices, "vertices");
    v.require_shape(2, 3, "(V, 3)");
    mesh.positions.resize(v.rows());
    for (py::ssize_t i = 0; i < v.rows(); ++i) mesh.positions[i] = Vec3(v.value(i, 0), v.value(i, 1), v.value(i, 2));
  }
  read_faces(mesh, faces);
  if (mesh.num_faces() == 0) throw MeshInputError{"faces: the mesh has no faces"};
  const Index nc = mesh.num_corners();
  if (!is_none(uvs)) {
    if (py::isinstance<py::dict>(uvs)) {
      for (const auto& [key, layer] : py::reinterpret_borrow<py::dict>(uvs)) {
        UvSet& set = mesh.uv_sets.emplace_back();
        set.name = py::str(key);
        read_per_corner(layer, "uvs['" + set.name + "']", nc, 2, set.values, set.corner);
      }
    } else {
      UvSet& set = mesh.uv_sets.emplace_back();
      read_per_corner(uvs, "uvs", nc, 2, set.values, set.corner);
    }
  }
  if (!is_none(normals)) read_per_corner(normals, "normals", nc, 3, mesh.normals, mesh.corner_normal);
  if (!is_none(materials)) {
    const NumberArray m(materials, "materials");
    m.require_shape(1, 1, "(F,)");
    if (m.rows() != py::ssize_t(mesh.num_faces()))
      throw MeshInputError{"materials: " + std::to_string(m.rows()) + " entries for " +
                           std::to_string(mesh.num_faces()) + " faces"};
    mesh.face_material.resize(mesh.num_faces());
    Index most = 0;
    for (Index f = 0; f < mesh.num_faces(); ++f) {
      mesh.face_material[f] = m.index(f, 0, "face");
      most = std::max(most, mesh.face_material[f]);
    }
    if (most > 1u << 20) throw MeshInputError{"materials: material index " + std::to_string(most) + " is implausibly large"};
    // Material borders are found by name (docs/attributes.md): the slot number is the name.
    for (Index i = 0; i <= most; ++i) mesh.material_names.push_back(std::to_string(i));
  }
  if (std::string problem = mesh.check_layout(); !problem.empty()) throw MeshInputError{problem};
  return mesh;
}

void read_morph_targets(PolyMesh& mesh, const py::handle& morph_targets) {
  if (is_none(morph_targets)) return;
  if (!py::isinstance<py::dict>(morph_targets))
    throw MeshInputError{"morph_targets: a dict {name: (V, 3) displacements}"};
  for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(morph_targets)) {
    MorphTarget& t = mesh.morph_targets.emplace_back();
    t.name = py::str(key);
    const std::string what = "morph_targets['" + t.name + "']";
    const NumberArray a(value, what);
    a.require_shape(2, 3, "(V, 3)");
    if (a.rows() != py::ssize_t(mesh.num_vertices()))
      throw MeshInputError{what + ": " + std::to_string(a.rows()) + " rows for " + std::to_string(mesh.num_vertices()) +
                           " vertices"};
    t.displacement.resize(mesh.num_vertices());
    for (py::ssize_t i = 0; i < a.rows(); ++i) {
      t.displacement[i] = Vec3(a.value(i, 0), a.value(i, 1), a.value(i, 2));
      if (!t.displacement[i].allFinite()) throw MeshInputError{what + ": vertex " + std::to_string(i) + " is not finite"};
    }
  }
}

PolyMesh mesh_from_object(const py::handle& mesh) {
  if (py::isinstance<py::dict>(mesh)) {
    const py::dict d = py::reinterpret_borrow<py::dict>(mesh);
    auto get = [&](const char* key) -> py::object {
      return d.contains(key) ? py::object(d[key]) : py::object(py::none());
    };
    if (!d.contains("vertices") || !d.contains("faces"))
      throw MeshInputError{"mesh: a dict needs the keys 'vertices' and 'faces'"};
    py::object faces = get("faces");
    if (!get("face_sizes").is_none()) faces = py::make_tuple(faces, get("face_sizes"));
    PolyMesh out = mesh_from_arrays(get("vertices"), faces, get("uvs"), get("normals"), get("materials"));
    read_morph_targets(out, get("morph_targets"));  // issue 34
    return out;
  }
  if (py::isinstance<py::tuple>(mesh)) {
    const py::tuple t = py::reinterpret_borrow<py::tuple>(mesh);
    if (t.size() == 2) return mesh_from_arrays(t[0], t[1], py::none(), py::none(), py::none());
    if (t.size() == 3)
      return mesh_from_arrays(t[0], py::make_tuple(t[1], t[2]), py::none(), py::none(), py::none());
  }
  throw MeshInputError{"mesh: expected a dict with 'vertices' and 'faces', or a tuple (vertices, faces[, face_sizes])"};
}

py::dict mesh_to_dict(const PolyMesh& mesh, bool uvs_as_dict) {
  const py::ssize_t nv = mesh.num_vertices(), nf = mesh.num_faces(), nc = mesh.num_corners();
  py::array_t<double> vertices({nv, py::ssize_t(3)});
  auto v = vertices.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < nv; ++i)
    for (int d = 0; d < 3; ++d) v(i, d) = mesh.positions[i][d];
  py::array_t<std::int32_t> corners(nc), sizes(nf);
  auto c = corners.mutable_unchecked<1>();
  auto s = sizes.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < nc; ++i) c(i) = std::int32_t(mesh.corner_vertex[i]);
  for (py::ssize_t f = 0; f < nf; ++f) s(f) = std::int32_t(mesh.face_size(Index(f)));
  py::dict out;
  out["vertices"] = vertices;
  out["faces"] = corners;
  out["face_sizes"] = sizes;
  auto per_corner = [nc](const auto& values, const std::vector<Index>& corner, int dims) {
    py::array_t<double> a({nc, py::ssize_t(dims)});
    auto w = a.mutable_unchecked<2>();
    for (py::ssize_t i = 0; i < nc; ++i)
      for (int d = 0; d < dims; ++d)
        w(i, d) = corner[i] == kInvalidIndex ? std::numeric_limits<double>::quiet_NaN() : values[corner[i]][d];
    return a;
  };
  if (mesh.has_uvs()) {
    if (uvs_as_dict) {
      py::dict layers;
      for (const UvSet& set : mesh.uv_sets) layers[py::str(set.name)] = per_corner(set.values, set.corner, 2);
      out["uvs"] = layers;
    } else {
      out["uvs"] = per_corner(mesh.uv_sets[0].values, mesh.uv_sets[0].corner, 2);
    }
  }
  if (mesh.has_normals()) out["normals"] = per_corner(mesh.normals, mesh.corner_normal, 3);
  if (!mesh.face_material.empty()) {
    py::array_t<std::int32_t> materials(nf);
    auto m = materials.mutable_unchecked<1>();
    for (py::ssize_t f = 0; f < nf; ++f) {
      const Index id = mesh.face_material[f];
      // Names are the input's slot numbers (mesh_from_arrays); a mesh read elsewhere keeps its ids.
      int slot = int(id);
      if (id == kInvalidIndex) slot = -1;
      else if (id < mesh.material_names.size()) {
        try { slot = std::stoi(mesh.material_names[id]); } catch (...) { slot = int(id); }
      }
      m(f) = slot;
    }
    out["materials"] = materials;
  }
  if (!mesh.morph_targets.empty()) {  // issue 34: blend shapes
    py::dict shapes;
    for (const MorphTarget& t : mesh.morph_targets) {
      py::array_t<double> d({nv, py::ssize_t(3)});
      auto w = d.mutable_unchecked<2>();
      for (py::ssize_t i = 0; i < nv; ++i)
        for (int k = 0; k < 3; ++k) w(i, k) = t.displacement[i][k];
      shapes[py::str(t.name)] = d;
    }
    out["morph_targets"] = shapes;
  }
  return out;
}

}  // namespace quadlod::python
