// quadlod — FBX control points behind assimp's aiMeshes (see fbx_control_points.h).
#include "io/fbx_control_points.h"

#include <assimp/scene.h>

#include <algorithm>
#include <map>
#include <tuple>

namespace quadlod::fbx {

namespace {

/// The text of an FBX object name before its class ("Cube\0\1Geometry" → "Cube").
std::string object_name(const std::string& stored) {
  const std::size_t cut = stored.find(std::string_view("\0\1", 2));
  return cut == std::string::npos ? stored : stored.substr(0, cut);
}

const Property* array_of(const Record& record, std::string_view child) {
  const Record* r = record.find(child);
  if (!r || r->properties.empty()) return nullptr;
  return &r->properties[0];
}

/// One Geometry record into `out`; "" or what is wrong with it.
std::string read_geometry(const Record& g, MeshGeometry& out) {
  out.name = object_name(g.string_property(1));
  const std::string where = "FBX Geometry '" + printable(out.name) + "': ";
  const Property* vertices = array_of(g, "Vertices");
  const Property* polygons = array_of(g, "PolygonVertexIndex");
  if (!vertices || !polygons) return {};  // a mesh without faces: nothing to map (no aiMesh either)
  if (vertices->type != 'd' && vertices->type != 'f') return where + "Vertices is not a real array";
  if (polygons->type != 'i' && polygons->type != 'l') return where + "PolygonVertexIndex is not an integer array";
  const std::vector<double>& v = vertices->reals;
  if (v.size() % 3 != 0) return where + "Vertices holds " + std::to_string(v.size()) + " numbers, not a multiple of 3";
  out.control_points.resize(v.size() / 3);
  for (std::size_t i = 0; i < out.control_points.size(); ++i) {
    out.control_points[i] = Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    if (!out.control_points[i].allFinite()) return where + "control point " + std::to_string(i) + " is not finite";
  }
  const std::int64_t count = static_cast<std::int64_t>(out.control_points.size());
  out.polygon_corners.reserve(polygons->integers.size());
  for (std::size_t c = 0; c < polygons->integers.size(); ++c) {
    std::int64_t i = polygons->integers[c];
    const bool last = i < 0;
    if (last) i = -(i + 1);  // ~i, without overflow on INT64_MIN: -(INT64_MIN + 1) fits
    if (i >= count) return where + "polygon corner " + std::to_string(c) + " names control point " + std::to_string(i) + " of " + std::to_string(count);
    out.polygon_corners.push_back(static_cast<Index>(i));
    if (last) out.polygon_offsets.push_back(static_cast<Index>(out.polygon_corners.size()));
  }
  if (out.polygon_offsets.back() != out.polygon_corners.size()) return where + "the last polygon is not closed (no negative index)";
  if (const Record* layer = g.find("LayerElementMaterial")) {
    const Record* mapping = layer->find("MappingInformationType");
    const Property* materials = array_of(*layer, "Materials");
    if (mapping && mapping->string_property(0) == "ByPolygon" && materials) {
      if (materials->integers.size() != static_cast<std::size_t>(out.num_polygons()))
        return where + "Materials holds " + std::to_string(materials->integers.size()) + " entries for " + std::to_string(out.num_polygons()) + " polygons";
      out.polygon_material = materials->integers;
    }
  }
  return {};
}

/// Which polygons an aiMesh holds by size: SortByPType splits a mesh of triangles and larger
/// polygons into one aiMesh of each (and removes points and lines).
enum SizeClass : unsigned { kTriangles = 1, kPolygons = 2 };

unsigned size_classes(const aiMesh& a) {
  unsigned classes = 0;
  for (unsigned f = 0; f < a.mNumFaces; ++f) classes |= a.mFaces[f].mNumIndices == 3 ? unsigned{kTriangles} : a.mFaces[f].mNumIndices > 3 ? unsigned{kPolygons} : 0u;
  return classes;
}

/// Whether aiMesh `a` is the polygons of `g` with material `material` (any material when
/// `material` is null) and a size in `classes`, and if so each aiMesh face's polygon.
bool matches(const aiMesh& a, const MeshGeometry& g, const std::int64_t* material, unsigned classes,
             std::vector<Index>& polygon_of_face) {
  polygon_of_face.clear();
  Index p = 0;
  const Index polygons = g.num_polygons();
  const auto skipped = [&](Index q) {  // not in this aiMesh: another material or size class
    const Index size = g.polygon_offsets[q + 1] - g.polygon_offsets[q];
    return (material && g.polygon_material[q] != *material) || size < 3 || !(classes & (size == 3 ? kTriangles : kPolygons));
  };
  for (unsigned f = 0; f < a.mNumFaces; ++f) {
    const aiFace& face = a.mFaces[f];
    while (p < polygons && skipped(p)) ++p;
    if (p == polygons) return false;
    const Index begin = g.polygon_offsets[p];
    if (face.mNumIndices != g.polygon_offsets[p + 1] - begin) return false;
    for (unsigned c = 0; c < face.mNumIndices; ++c) {
      const unsigned v = face.mIndices[c];
      if (v >= a.mNumVertices) return false;
      const Vec3& cp = g.control_points[g.polygon_corners[begin + c]];
      const aiVector3D& ap = a.mVertices[v];
      if (ap.x != static_cast<float>(cp.x()) || ap.y != static_cast<float>(cp.y()) || ap.z != static_cast<float>(cp.z()))
        return false;
    }
    polygon_of_face.push_back(p++);
  }
  // Every polygon of that material and size must be in the aiMesh: none left over.
  while (p < polygons && skipped(p)) ++p;
  return p == polygons && a.mNumFaces > 0;
}

}  // namespace

GeometryRead read_mesh_geometries(std::string_view bytes, const ParseParams& params) {
  GeometryRead out;
  ParseResult parsed = parse_binary_fbx(bytes, params);
  if (!parsed.ok()) {
    out.error = parsed.error;
    return out;
  }
  if (const Record* creator = parsed.document.find("Creator")) out.creator = creator->string_property(0);
  const Record* objects = parsed.document.find("Objects");
  if (!objects) return out;
  for (const Record& r : objects->children) {
    if (r.name != "Geometry" || r.string_property(2) != "Mesh") continue;
    MeshGeometry g;
    if (std::string problem = read_geometry(r, g); !problem.empty()) {
      out.error = problem;
      out.geometries.clear();
      return out;
    }
    if (g.num_polygons() > 0) out.geometries.push_back(std::move(g));
  }
  return out;
}

bool control_points_are_vertices(const GeometryRead& read) {
  return read.ok() && read.creator.find("Open Asset Import Library") == std::string::npos;
}

bool control_point_faces(const aiScene& scene, const std::vector<unsigned>& group,
                         const std::vector<MeshGeometry>& geometries, ControlPointFaces& out) {
  out = {};
  struct Face {
    Index geometry, polygon;
    unsigned mesh, face;
  };
  std::vector<Face> faces;
  std::vector<Index> polygon_of_face;
  // (geometry, material) pairs already matched: two aiMeshes are never the same polygons.
  std::map<std::tuple<Index, std::int64_t, unsigned>, char> used;
  for (unsigned m : group) {
    if (m >= scene.mNumMeshes) return false;
    const aiMesh& a = *scene.mMeshes[m];
    const unsigned classes = size_classes(a);
    bool found = false;
    for (Index g = 0; g < geometries.size() && !found; ++g) {
      const MeshGeometry& geometry = geometries[g];
      // Candidate materials in order of first use (assimp's order), or the whole geometry.
      std::vector<std::int64_t> materials;
      for (std::int64_t mat : geometry.polygon_material)
        if (std::find(materials.begin(), materials.end(), mat) == materials.end()) materials.push_back(mat);
      const bool one_material = materials.size() <= 1;
      for (std::size_t k = 0; k < (one_material ? 1 : materials.size()) && !found; ++k) {
        const std::int64_t key = one_material ? -1 : materials[k];
        if (used.count({g, key, classes})) continue;
        if (!matches(a, geometry, one_material ? nullptr : &materials[k], classes, polygon_of_face)) continue;
        used[{g, key, classes}] = 1;
        for (unsigned f = 0; f < a.mNumFaces; ++f) faces.push_back({g, polygon_of_face[f], m, f});
        found = true;
      }
    }
    if (!found) return false;
  }
  std::sort(faces.begin(), faces.end(), [](const Face& x, const Face& y) {
    return x.geometry != y.geometry ? x.geometry < y.geometry : x.polygon < y.polygon;
  });
  // Vertices: the control points used, numbered in (geometry, control point) order.
  std::vector<Index> first(geometries.size() + 1, 0);
  for (Index g = 0; g < geometries.size(); ++g) first[g + 1] = first[g] + static_cast<Index>(geometries[g].control_points.size());
  std::vector<char> cp_used(first.back(), 0);
  for (const Face& f : faces) {
    const MeshGeometry& g = geometries[f.geometry];
    for (Index c = g.polygon_offsets[f.polygon]; c < g.polygon_offsets[f.polygon + 1]; ++c)
      cp_used[first[f.geometry] + g.polygon_corners[c]] = 1;
  }
  std::vector<Index> vertex_of(first.back(), kInvalidIndex);
  for (Index g = 0; g < geometries.size(); ++g)
    for (Index i = 0; i < geometries[g].control_points.size(); ++i)
      if (cp_used[first[g] + i]) {
        vertex_of[first[g] + i] = static_cast<Index>(out.positions.size());
        out.positions.push_back(geometries[g].control_points[i]);
      }
  for (const Face& f : faces) {
    const MeshGeometry& g = geometries[f.geometry];
    const aiFace& face = scene.mMeshes[f.mesh]->mFaces[f.face];
    const Index begin = g.polygon_offsets[f.polygon];
    for (unsigned c = 0; c < face.mNumIndices; ++c) {
      out.mesh.push_back(f.mesh);
      out.mesh_vertex.push_back(face.mIndices[c]);
      out.vertex.push_back(vertex_of[first[f.geometry] + g.polygon_corners[begin + c]]);
    }
    out.face_offsets.push_back(static_cast<Index>(out.vertex.size()));
  }
  return true;
}

}  // namespace quadlod::fbx
