// Deterministic surface and curve sampling.
//
// References: Steele, Lea, Flood, "Fast splittable pseudorandom number generators" (OOPSLA 2014)
// for splitmix64; Blackman, Vigna, "Scrambled linear pseudorandom number generators" (2018/2021)
// for xoshiro256**; Osada, Funkhouser, Chazelle, Dobkin, "Shape distributions" (TOG 2002), Eq. 1
// for the sqrt(r1) barycentric method.
#include "geometry/sampling.h"

#include <algorithm>
#include <cmath>

namespace quadlod {

std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

namespace {
inline std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
}  // namespace

Xoshiro256::Xoshiro256(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t sm = seed ^ (stream * 0xD1B54A32D192ED03ULL);
  for (auto& w : s_) w = splitmix64(sm);
  // splitmix64 never yields four zero words in a row, so the state is valid.
}

Xoshiro256 Xoshiro256::from_state(const std::array<std::uint64_t, 4>& state) {
  Xoshiro256 g(0);
  for (int i = 0; i < 4; ++i) g.s_[i] = state[i];
  return g;
}

std::uint64_t Xoshiro256::next() {
  const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
  const std::uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = rotl(s_[3], 45);
  return result;
}

TriangleSoup fan_triangulate(const PolyMesh& mesh) {
  TriangleSoup soup;
  soup.triangles.reserve(mesh.num_corners() >= 2 * mesh.num_faces()
                             ? mesh.num_corners() - 2 * mesh.num_faces()
                             : 0);
  soup.face.reserve(soup.triangles.capacity());
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const auto vs = mesh.face_vertices(f);
    const Vec3& p0 = mesh.positions[vs[0]];
    for (std::size_t i = 1; i + 1 < vs.size(); ++i) {
      soup.triangles.push_back({p0, mesh.positions[vs[i]], mesh.positions[vs[i + 1]]});
      soup.face.push_back(f);
    }
  }
  return soup;
}

double triangle_area(const std::array<Vec3, 3>& t) {
  return 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).norm();
}

SurfaceSamples sample_triangles(const TriangleSoup& soup, std::uint64_t count, std::uint64_t seed,
                                std::uint64_t stream) {
  SurfaceSamples out;
  const std::size_t n = soup.triangles.size();
  std::vector<double> cumulative(n);
  double total = 0.0;
  for (std::size_t t = 0; t < n; ++t) {
    total += triangle_area(soup.triangles[t]);
    cumulative[t] = total;
  }
  out.total_area = total;
  if (!(total > 0.0) || !std::isfinite(total) || count == 0) return out;

  // The last triangle with positive area: the target when rounding makes u reach the total.
  std::size_t last_positive = n - 1;
  while (last_positive > 0 && cumulative[last_positive] == cumulative[last_positive - 1])
    --last_positive;

  out.points.resize(count);
  out.triangle.resize(count);
  Xoshiro256 rng(seed, stream);
  for (std::uint64_t k = 0; k < count; ++k) {
    const double u = rng.uniform01() * total;
    // First t with cumulative[t] > u: a zero-area triangle has cumulative equal to its
    // predecessor's, so the predecessor (or an earlier triangle) is always found first.
    std::size_t t = static_cast<std::size_t>(
        std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin());
    if (t >= n) t = last_positive;
    const double r1 = rng.uniform01();
    const double r2 = rng.uniform01();
    const double s = std::sqrt(r1);
    const auto& tri = soup.triangles[t];
    out.points[k] = (1.0 - s) * tri[0] + (s * (1.0 - r2)) * tri[1] + (s * r2) * tri[2];
    out.triangle[k] = static_cast<Index>(t);
  }
  return out;
}

CurveSamples sample_segments_by_arc_length(std::span<const std::array<Vec3, 2>> segments,
                                           std::uint64_t count) {
  CurveSamples out;
  double total = 0.0;
  for (const auto& s : segments) total += (s[1] - s[0]).norm();
  out.total_length = total;
  if (!(total > 0.0) || !std::isfinite(total) || count == 0) return out;

  out.points.reserve(count);
  const double step = total / static_cast<double>(count);
  double start = 0.0;  // arc length at the start of the current segment
  std::size_t seg = 0;
  for (std::uint64_t k = 0; k < count; ++k) {
    const double target = (static_cast<double>(k) + 0.5) * step;
    // Advance to the segment containing `target`; the last segment takes any rounding overshoot.
    while (seg + 1 < segments.size()) {
      const double len = (segments[seg][1] - segments[seg][0]).norm();
      if (start + len > target) break;
      start += len;
      ++seg;
    }
    const auto& s = segments[seg];
    const double len = (s[1] - s[0]).norm();
    double t = len > 0.0 ? (target - start) / len : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    out.points.push_back(s[0] + t * (s[1] - s[0]));
  }
  return out;
}

}  // namespace quadlod
