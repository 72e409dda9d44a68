// See storage_precision.h.
#include "pipeline/storage_precision.h"

#include <cfloat>
#include <cmath>
#include <cstring>
#include <unordered_map>

namespace quadlod {

namespace {

bool rounds_to_float(double x) { return std::isfinite(x) && std::abs(x) <= double(FLT_MAX); }

Vec3 rounded(const Vec3& p) { return {double(float(p.x())), double(float(p.y())), double(float(p.z()))}; }

struct FloatKey {
  std::uint32_t x, y, z;
  bool operator==(const FloatKey&) const = default;
};
struct FloatKeyHash {
  std::size_t operator()(const FloatKey& k) const {
    std::uint64_t h = k.x;
    h = h * 0x9E3779B97F4A7C15ull ^ k.y;
    h = h * 0x9E3779B97F4A7C15ull ^ k.z;
    return std::size_t(h ^ (h >> 29));
  }
};
FloatKey key_of(const Vec3& p) {
  const float f[3] = {float(p.x()), float(p.y()), float(p.z())};
  FloatKey k;
  std::memcpy(&k.x, &f[0], 4);
  std::memcpy(&k.y, &f[1], 4);
  std::memcpy(&k.z, &f[2], 4);
  return k;
}

}  // namespace

std::optional<PolyMesh> with_float32_positions(const PolyMesh& mesh) {
  bool changes = false;
  for (const Vec3& p : mesh.positions) {
    for (int i = 0; i < 3; ++i)
      if (!rounds_to_float(p[i])) return std::nullopt;
    changes = changes || rounded(p) != p;
  }
  if (!changes) return std::nullopt;
  PolyMesh out = mesh;
  for (Vec3& p : out.positions) p = rounded(p);
  return out;
}

void restore_input_positions(const PolyMesh& input, PolyMesh& output) {
  std::unordered_map<FloatKey, Index, FloatKeyHash> at;
  at.reserve(input.positions.size());
  for (Index v = 0; v < input.num_vertices(); ++v) at.emplace(key_of(input.positions[v]), v);
  for (Vec3& p : output.positions) {
    if (rounded(p) != p) continue;  // a new placement off the float32 grid: not an input point
    const auto it = at.find(key_of(p));
    if (it != at.end()) p = input.positions[it->second];
  }
}

}  // namespace quadlod
