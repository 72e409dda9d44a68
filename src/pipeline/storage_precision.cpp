// See storage_precision.h.
#include "pipeline/storage_precision.h"

#include <cfloat>
#include <cmath>
#include <cstring>
#include <algorithm>
#include <compare>
#include <vector>

namespace quadlod {

namespace {

bool rounds_to_float(double x) { return std::isfinite(x) && std::abs(x) <= double(FLT_MAX); }

// double → float32 → double. Through a volatile float: g++ 12.2's SLP vectorizer drops the
// float truncation of the first two coordinates of `Vec3(double(float(p.x())), …)` and of the
// same loop at -O2 (it stores the doubles unchanged; seen in its output, tested below by
// Simplify.DecisionsAreOnFloat32SoTheStoragePrecisionDoesNotMatter).
double to_float32(double x) {
  volatile float f = static_cast<float>(x);
  return static_cast<double>(f);
}

template <class V>
V rounded(const V& p) {
  V r;
  for (int i = 0; i < int(V::RowsAtCompileTime); ++i) r[i] = to_float32(p[i]);
  return r;
}

// The float32 bits of a (rounded) point, as a sort key.
struct FloatKey {
  std::uint32_t c[3] = {0, 0, 0};
  auto operator<=>(const FloatKey&) const = default;
};
template <class V>
FloatKey key_of(const V& p) {
  FloatKey k;
  for (int i = 0; i < int(V::RowsAtCompileTime); ++i) {
    const float f = float(p[i]);
    std::memcpy(&k.c[i], &f, 4);
  }
  return k;
}

// False when a value cannot be rounded (beyond float32's range, or not finite); `changes` is
// set when rounding moves one.
template <class V>
bool check(const std::vector<V>& values, bool& changes) {
  for (const V& p : values) {
    for (int i = 0; i < int(V::RowsAtCompileTime); ++i)
      if (!rounds_to_float(p[i])) return false;
    changes = changes || rounded(p) != p;
  }
  return true;
}

template <class V>
void round_all(std::vector<V>& values) {
  for (V& p : values) p = rounded(p);
}

bool roundable(const PolyMesh& mesh, bool& changes) {
  if (!check(mesh.positions, changes) || !check(mesh.normals, changes)) return false;
  for (const UvSet& set : mesh.uv_sets)
    if (!check(set.values, changes)) return false;
  return true;
}

// Values of `output` that are exactly a rounded value of `input` get that input value back.
// A sorted table rather than a hash map: one allocation instead of one a vertex (the map was
// 4 % of the 1M grid's run, issue 20).
template <class V>
void restore(const std::vector<V>& input, std::vector<V>& output) {
  struct Entry {
    FloatKey key;
    std::size_t index;
  };
  std::vector<Entry> table(input.size());
  for (std::size_t i = 0; i < input.size(); ++i) table[i] = {key_of(input[i]), i};
  // By key, the lowest index first; then one entry a key: the lowest-numbered input value.
  std::sort(table.begin(), table.end(), [](const Entry& a, const Entry& b) {
    return a.key != b.key ? a.key < b.key : a.index < b.index;
  });
  table.erase(std::unique(table.begin(), table.end(), [](const Entry& a, const Entry& b) { return a.key == b.key; }),
              table.end());
  for (V& p : output) {
    if (rounded(p) != p) continue;  // a new value off the float32 grid: not an input value
    const FloatKey k = key_of(p);
    const auto it = std::lower_bound(table.begin(), table.end(), k, [](const Entry& e, const FloatKey& key) { return e.key < key; });
    if (it != table.end() && it->key == k) p = input[it->index];
  }
}

}  // namespace

bool float32_rounding_changes(const PolyMesh& mesh) {
  bool changes = false;
  return roundable(mesh, changes) && changes;
}

std::optional<PolyMesh> round_to_float32_in_place(PolyMesh& mesh) {
  if (!float32_rounding_changes(mesh)) return std::nullopt;
  PolyMesh exact;
  exact.positions = mesh.positions;
  exact.normals = mesh.normals;
  exact.uv_sets.resize(mesh.uv_sets.size());
  for (std::size_t k = 0; k < mesh.uv_sets.size(); ++k) exact.uv_sets[k].values = mesh.uv_sets[k].values;
  round_all(mesh.positions);
  round_all(mesh.normals);
  for (UvSet& set : mesh.uv_sets) round_all(set.values);
  return exact;
}

void put_back_exact_values(PolyMesh&& exact, PolyMesh& mesh) {
  mesh.positions = std::move(exact.positions);
  mesh.normals = std::move(exact.normals);
  for (std::size_t k = 0; k < mesh.uv_sets.size() && k < exact.uv_sets.size(); ++k)
    mesh.uv_sets[k].values = std::move(exact.uv_sets[k].values);
}

void restore_input_values(const PolyMesh& input, PolyMesh& output) {
  restore(input.positions, output.positions);
  restore(input.normals, output.normals);
  for (std::size_t k = 0; k < std::min(input.uv_sets.size(), output.uv_sets.size()); ++k)
    restore(input.uv_sets[k].values, output.uv_sets[k].values);
}

}  // namespace quadlod
