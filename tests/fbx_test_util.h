// A writer of binary FBX bytes for tests (tests/test_fbx_binary.cpp): records with properties and
// nested records, FBX 7.4 (32-bit offsets) or 7.5 (64-bit), arrays raw or zlib-compressed.
#pragma once

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace quadlod::fbx_test {

/// One encoded property (type code + payload).
struct Prop {
  std::string bytes;
};

template <class T>
inline void put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.append(b, sizeof(T));
}

inline Prop I(std::int32_t v) { Prop p{"I"}; put(p.bytes, v); return p; }
inline Prop L(std::int64_t v) { Prop p{"L"}; put(p.bytes, v); return p; }
inline Prop D(double v) { Prop p{"D"}; put(p.bytes, v); return p; }
inline Prop F(float v) { Prop p{"F"}; put(p.bytes, v); return p; }
inline Prop Y(std::int16_t v) { Prop p{"Y"}; put(p.bytes, v); return p; }
inline Prop C(bool v) { Prop p{"C"}; put(p.bytes, static_cast<std::uint8_t>(v)); return p; }
inline Prop S(const std::string& s, char type = 'S') {
  Prop p{std::string(1, type)};
  put(p.bytes, static_cast<std::uint32_t>(s.size()));
  p.bytes += s;
  return p;
}
/// An array property of `type` ('d', 'f', 'i', 'l', 'b'), zlib-compressed when `zlib`.
template <class T>
inline Prop array(char type, const std::vector<T>& values, bool zlib = false) {
  std::string raw(values.size() * sizeof(T), '\0');
  if (!values.empty()) std::memcpy(raw.data(), values.data(), raw.size());
  std::string data = raw;
  if (zlib) {
    uLongf n = compressBound(static_cast<uLong>(raw.size()));
    data.resize(n);
    compress(reinterpret_cast<Bytef*>(data.data()), &n, reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size()));
    data.resize(n);
  }
  Prop p{std::string(1, type)};
  put(p.bytes, static_cast<std::uint32_t>(values.size()));
  put(p.bytes, static_cast<std::uint32_t>(zlib ? 1 : 0));
  put(p.bytes, static_cast<std::uint32_t>(data.size()));
  p.bytes += data;
  return p;
}

struct Rec {
  std::string name;
  std::vector<Prop> props;
  std::vector<Rec> children;
};

inline void encode(const Rec& r, bool wide, std::string& out) {
  const std::size_t start = out.size();
  std::string props;
  for (const Prop& p : r.props) props += p.bytes;
  const auto field = [&](std::uint64_t v) {
    if (wide) put(out, v); else put(out, static_cast<std::uint32_t>(v));
  };
  field(0);  // end offset, patched below
  field(r.props.size());
  field(props.size());
  out.push_back(static_cast<char>(r.name.size()));
  out += r.name;
  out += props;
  for (const Rec& c : r.children) encode(c, wide, out);
  if (!r.children.empty()) out.append(wide ? 25 : 13, '\0');
  const std::uint64_t end = out.size();
  if (wide) std::memcpy(out.data() + start, &end, 8);
  else { const std::uint32_t e = static_cast<std::uint32_t>(end); std::memcpy(out.data() + start, &e, 4); }
}

/// A whole file: header, the records, the closing NULL record (no footer).
inline std::string file(const std::vector<Rec>& records, std::uint32_t version = 7400) {
  std::string out("Kaydara FBX Binary  \0\x1a\0", 23);
  put(out, version);
  for (const Rec& r : records) encode(r, version >= 7500, out);
  out.append(version >= 7500 ? 25 : 13, '\0');
  return out;
}

/// A mesh for assimp: one Geometry (control points, polygons with the last index of each
/// stored as -(i + 1), optional per-polygon material slots) under one Model, `creator` as the
/// file's Creator.
inline std::string mesh_file(const std::vector<double>& control_points, const std::vector<std::vector<std::int32_t>>& polygons,
                             const std::vector<std::int32_t>& polygon_material = {},
                             const std::string& creator = "quadlod test", std::uint32_t version = 7400) {
  std::vector<std::int32_t> index;
  for (const auto& p : polygons)
    for (std::size_t i = 0; i < p.size(); ++i) index.push_back(i + 1 == p.size() ? -(p[i] + 1) : p[i]);
  Rec geometry{"Geometry", {L(100), S(std::string("part\0\1Geometry", 14)), S("Mesh")},
               {{"GeometryVersion", {I(124)}, {}},
                {"Vertices", {array('d', control_points, true)}, {}},
                {"PolygonVertexIndex", {array('i', index)}, {}}}};
  std::vector<Rec> objects{geometry};
  std::vector<Rec> connections{{"C", {S("OO"), L(100), L(200)}, {}}, {"C", {S("OO"), L(200), L(0)}, {}}};
  if (!polygon_material.empty()) {
    objects[0].children.push_back({"LayerElementMaterial", {I(0)},
                                   {{"Version", {I(101)}, {}},
                                    {"Name", {S("")}, {}},
                                    {"MappingInformationType", {S("ByPolygon")}, {}},
                                    {"ReferenceInformationType", {S("IndexToDirect")}, {}},
                                    {"Materials", {array('i', polygon_material)}, {}}}});
    objects[0].children.push_back({"Layer", {I(0)},
                                   {{"Version", {I(100)}, {}},
                                    {"LayerElement", {}, {{"Type", {S("LayerElementMaterial")}, {}}, {"TypedIndex", {I(0)}, {}}}}}});
    for (int m = 0; m < 2; ++m) {
      objects.push_back({"Material", {L(300 + m), S(std::string("mat") + char('a' + m) + std::string("\0\1Material", 10)), S("")},
                         {{"Version", {I(102)}, {}}, {"ShadingModel", {S("phong")}, {}}}});
      connections.push_back({"C", {S("OO"), L(300 + m), L(200)}, {}});
    }
  }
  objects.push_back({"Model", {L(200), S(std::string("part\0\1Model", 11)), S("Mesh")}, {{"Version", {I(232)}, {}}}});
  return file({{"FBXHeaderExtension", {}, {{"FBXHeaderVersion", {I(1003)}, {}}, {"FBXVersion", {I(static_cast<std::int32_t>(version))}, {}}}},
               {"Creator", {S(creator)}, {}},
               {"Objects", {}, objects},
               {"Connections", {}, connections}},
              version);
}

}  // namespace quadlod::fbx_test
