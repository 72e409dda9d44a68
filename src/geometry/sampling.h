// Deterministic sampling of surfaces and polylines (the sample sets of `quadlod eval`,
// docs/metrics.md §2 and §5).
//
// Everything here is bit-reproducible for a fixed seed: the generator is xoshiro256** seeded by
// splitmix64 (both fully specified below, no <random> distributions, whose output differs between
// standard libraries), and every conversion to a double is written out.
#pragma once

#include "quadlod/mesh.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace quadlod {

/// splitmix64 step (Steele, Lea, Flood 2014): advances `state` by 0x9E3779B97F4A7C15 and
/// returns the mixed value.
std::uint64_t splitmix64(std::uint64_t& state);

/// xoshiro256** 1.0 (Blackman & Vigna 2018). The four state words are the first four splitmix64
/// outputs starting from `seed ^ (stream · 0xD1B54A32D192ED03)`, so (seed, stream) pairs give
/// independent, reproducible sequences.
class Xoshiro256 {
 public:
  Xoshiro256(std::uint64_t seed, std::uint64_t stream = 0);
  /// A generator with the given raw state (not all zero), for known-answer tests.
  static Xoshiro256 from_state(const std::array<std::uint64_t, 4>& state);
  std::uint64_t next();
  /// Uniform double in [0, 1): the top 53 bits of next() times 2^-53.
  double uniform01() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t s_[4];
};

/// The triangles a polygon mesh is measured by: each face (v0, v1, …, v_{k-1}) is fanned from its
/// corner 0 into (v0, v_i, v_{i+1}), i = 1…k-2. Zero-area triangles are kept (the distance target
/// is their point set); sampling gives them no samples.
struct TriangleSoup {
  std::vector<std::array<Vec3, 3>> triangles;
  std::vector<Index> face;  ///< face of each triangle
};
TriangleSoup fan_triangulate(const PolyMesh& mesh);

/// Area of a triangle: ½|(b − a) × (c − a)|.
double triangle_area(const std::array<Vec3, 3>& t);

struct SurfaceSamples {
  std::vector<Vec3> points;
  std::vector<Index> triangle;  ///< triangle (index into the soup) each point lies on
  double total_area = 0.0;      ///< sum of the triangle areas
};

/// `count` i.i.d. area-weighted uniform points on the union of the triangles, drawn from
/// Xoshiro256(seed, stream). For each sample, in this order:
///   u = uniform01() · total_area  → triangle t = first index with cumulative_area[t] > u
///   r1 = uniform01(), r2 = uniform01(), s = sqrt(r1)
///   point = (1 − s)·a + s(1 − r2)·b + s·r2·c          (Osada et al. 2002, Eq. 1)
/// Zero-area triangles are never chosen. Empty result when the total area is zero.
SurfaceSamples sample_triangles(const TriangleSoup& soup, std::uint64_t count, std::uint64_t seed,
                                std::uint64_t stream);

struct CurveSamples {
  std::vector<Vec3> points;
  double total_length = 0.0;
};

/// `count` points spaced evenly by arc length over the concatenation of `segments` (in order):
/// point k lies at arc length (k + ½)·L / count, L = total length (the midpoint rule). Empty when
/// L = 0 or count = 0. Deterministic, no randomness.
CurveSamples sample_segments_by_arc_length(std::span<const std::array<Vec3, 2>> segments,
                                           std::uint64_t count);

}  // namespace quadlod
