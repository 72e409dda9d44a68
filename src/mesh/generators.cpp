#include "quadlod/generators.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace quadlod {

namespace {

// Appends a quad with per-corner UVs taken from a (columns+1)×(rows+1) UV lattice.
struct LatticeBuilder {
  PolyMesh& mesh;
  Index uv_columns;  // lattice points per row of the UV grid
  Index uv_index(Index i, Index j) const { return j * uv_columns + i; }
  void quad(std::array<Index, 4> v, std::array<Index, 4> uv) {
    const Index f = mesh.add_face(std::span<const Index>(v.data(), 4));
    for (Index k = 0; k < 4; ++k) mesh.uv_sets[0].corner[mesh.face_begin(f) + k] = uv[k];
  }
};

void add_uv_lattice(PolyMesh& mesh, Index n, Index m) {
  mesh.uv_sets.resize(1);
  for (Index j = 0; j <= m; ++j)
    for (Index i = 0; i <= n; ++i) mesh.uv_sets[0].values.emplace_back(double(i) / n, double(j) / m);
  mesh.uv_sets[0].corner.reserve(4ull * n * m);
}


}  // namespace

PolyMesh make_grid(Index n, Index m, double width, double height) {
  PolyMesh mesh;
  for (Index j = 0; j <= m; ++j)
    for (Index i = 0; i <= n; ++i) mesh.add_vertex(Vec3(width * i / n, height * j / m, 0.0));
  add_uv_lattice(mesh, n, m);
  auto id = [&](Index i, Index j) { return j * (n + 1) + i; };
  for (Index j = 0; j < m; ++j)
    for (Index i = 0; i < n; ++i) {
      const std::array<Index, 4> v{id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)};
      const Index f = mesh.add_face(std::span<const Index>(v.data(), 4));
      for (Index k = 0; k < 4; ++k) mesh.uv_sets[0].corner[mesh.face_begin(f) + k] = v[k];
    }
  return mesh;
}

PolyMesh make_torus(Index n, Index m, double major_radius, double minor_radius) {
  PolyMesh mesh;
  const double two_pi = 2.0 * std::numbers::pi;
  for (Index i = 0; i < n; ++i)
    for (Index j = 0; j < m; ++j) {
      const double u = two_pi * i / n, v = two_pi * j / m;
      const double r = major_radius + minor_radius * std::cos(v);
      mesh.add_vertex(Vec3(r * std::cos(u), r * std::sin(u), minor_radius * std::sin(v)));
    }
  add_uv_lattice(mesh, n, m);
  LatticeBuilder b{mesh, n + 1};
  auto id = [&](Index i, Index j) { return (i % n) * m + (j % m); };
  for (Index i = 0; i < n; ++i)
    for (Index j = 0; j < m; ++j) {
      // Outward: (u, v) increasing gives an outward normal with this vertex order.
      b.quad({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)},
             {b.uv_index(i, j), b.uv_index(i + 1, j), b.uv_index(i + 1, j + 1), b.uv_index(i, j + 1)});
    }
  return mesh;
}

PolyMesh make_cylinder(Index n, Index m, double radius, double height) {
  PolyMesh mesh;
  const double two_pi = 2.0 * std::numbers::pi;
  for (Index j = 0; j <= m; ++j)
    for (Index i = 0; i < n; ++i) {
      const double a = two_pi * i / n;
      mesh.add_vertex(Vec3(radius * std::cos(a), radius * std::sin(a), height * j / m));
    }
  add_uv_lattice(mesh, n, m);
  LatticeBuilder b{mesh, n + 1};
  auto id = [&](Index i, Index j) { return j * n + (i % n); };
  for (Index j = 0; j < m; ++j)
    for (Index i = 0; i < n; ++i) {
      b.quad({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)},
             {b.uv_index(i, j), b.uv_index(i + 1, j), b.uv_index(i + 1, j + 1), b.uv_index(i, j + 1)});
    }
  return mesh;
}

PolyMesh make_cube(Index k, double size) {
  // Vertices on the cube's surface lattice, shared between sides through a lookup keyed by the
  // integer lattice coordinate (each in 0..k).
  PolyMesh mesh;
  std::vector<Index> lattice(std::size_t(k + 1) * (k + 1) * (k + 1), kInvalidIndex);
  auto vertex = [&](Index x, Index y, Index z) {
    Index& slot = lattice[(std::size_t(z) * (k + 1) + y) * (k + 1) + x];
    if (slot == kInvalidIndex)
      slot = mesh.add_vertex(Vec3(size * (double(x) / k - 0.5), size * (double(y) / k - 0.5),
                                  size * (double(z) / k - 0.5)));
    return slot;
  };
  // Six sides as (fixed axis, fixed value, axis a, axis b) with a × b pointing outward.
  struct Side { int fixed; Index value; int a; int b; };
  const Side sides[6] = {{2, k, 0, 1}, {2, 0, 1, 0}, {0, k, 1, 2},
                         {0, 0, 2, 1}, {1, k, 2, 0}, {1, 0, 0, 2}};
  add_uv_lattice(mesh, k, k);
  LatticeBuilder b{mesh, k + 1};
  for (const Side& s : sides)
    for (Index j = 0; j < k; ++j)
      for (Index i = 0; i < k; ++i) {
        auto at = [&](Index u, Index v) {
          Index c[3];
          c[s.fixed] = s.value;
          c[s.a] = u;
          c[s.b] = v;
          return vertex(c[0], c[1], c[2]);
        };
          b.quad({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)},
               {b.uv_index(i, j), b.uv_index(i + 1, j), b.uv_index(i + 1, j + 1), b.uv_index(i, j + 1)});
      }
  return mesh;
}

PolyMesh make_demo_vase(Index segments, Index rings) {
  PolyMesh mesh;
  const double two_pi = 2.0 * std::numbers::pi;
  const double height = 2.0;
  // Profile radius along the height: a bulging body, a narrow neck and a lip.
  auto radius = [&](double t) {
    return 0.45 + 0.35 * std::sin(std::numbers::pi * t * 0.9) + 0.06 * std::sin(6.0 * two_pi * t) -
           0.25 * std::exp(-std::pow((t - 0.85) / 0.07, 2.0));
  };
  for (Index j = 0; j <= rings; ++j) {
    const double t = double(j) / rings;
    for (Index i = 0; i < segments; ++i) {
      const double a = two_pi * i / segments;
      const double r = radius(t);
      mesh.add_vertex(Vec3(r * std::cos(a), r * std::sin(a), height * t));
    }
  }
  const Index pole = mesh.add_vertex(Vec3(0.0, 0.0, -0.05));
  auto id = [&](Index i, Index j) { return j * segments + (i % segments); };

  // UVs: the body is a cylindrical chart (with a seam at i = 0 / segments), the caps are discs.
  mesh.uv_sets.resize(1);
  for (Index j = 0; j <= rings; ++j)
    for (Index i = 0; i <= segments; ++i) mesh.uv_sets[0].values.emplace_back(double(i) / segments, 0.5 * j / rings);
  const Index disc_base = static_cast<Index>(mesh.uv_sets[0].values.size());
  for (Index i = 0; i < segments; ++i) {
    const double a = two_pi * i / segments;
    mesh.uv_sets[0].values.emplace_back(0.25 + 0.2 * std::cos(a), 0.75 + 0.2 * std::sin(a));
  }
  const Index pole_uv = static_cast<Index>(mesh.uv_sets[0].values.size());
  mesh.uv_sets[0].values.emplace_back(0.25, 0.75);
  const Index lid_base = static_cast<Index>(mesh.uv_sets[0].values.size());
  for (Index i = 0; i < segments; ++i) {
    const double a = two_pi * i / segments;
    mesh.uv_sets[0].values.emplace_back(0.75 + 0.2 * std::cos(a), 0.75 + 0.2 * std::sin(a));
  }
  auto body_uv = [&](Index i, Index j) { return j * (segments + 1) + i; };

  auto set_uvs = [&](Index f, std::initializer_list<Index> uv) {
    Index c = mesh.face_begin(f);
    for (Index u : uv) mesh.uv_sets[0].corner[c++] = u;
  };
  for (Index j = 0; j < rings; ++j)
    for (Index i = 0; i < segments; ++i)
      set_uvs(mesh.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)}),
              {body_uv(i, j), body_uv(i + 1, j), body_uv(i + 1, j + 1), body_uv(i, j + 1)});
  // Bottom fan: faces point down (-Z), so go clockwise seen from above.
  for (Index i = 0; i < segments; ++i)
    set_uvs(mesh.add_face({id(i + 1, 0), id(i, 0), pole}),
            {disc_base + (i + 1) % segments, disc_base + i, pole_uv});
  // Top lid: one n-gon facing +Z.
  std::vector<Index> lid(segments), lid_uv(segments);
  for (Index i = 0; i < segments; ++i) {
    lid[i] = id(i, rings);
    lid_uv[i] = lid_base + i;
  }
  const Index f = mesh.add_face(lid);
  std::copy(lid_uv.begin(), lid_uv.end(), mesh.uv_sets[0].corner.begin() + mesh.face_begin(f));
  return mesh;
}

}  // namespace quadlod

namespace quadlod {

SkinnedMesh make_bending_tube(Index around, Index along, Index bones, double radius, double length,
                              double blend, Index frames, double max_angle_deg) {
  SkinnedMesh out;
  out.mesh = make_cylinder(around, along, radius, length);
  const double bone_length = length / bones;
  Skeleton& skeleton = out.rig.skeleton;
  for (Index k = 0; k < bones; ++k) {
    Joint j;
    j.name = "bone" + std::to_string(k);
    j.parent = k == 0 ? kInvalidIndex : k - 1;
    j.rest.translation = Vec3(0, 0, k == 0 ? 0.0 : bone_length);
    Mat4 bind = Mat4::Identity();
    bind(2, 3) = k * bone_length;  // the rest global of joint k
    j.inverse_bind = bind.inverse();
    skeleton.joints.push_back(j);
  }
  const double half = blend * bone_length;
  std::vector<std::vector<Influence>> per_vertex(out.mesh.num_vertices());
  for (Index v = 0; v < out.mesh.num_vertices(); ++v) {
    const double z = out.mesh.positions[v].z();
    Index bone = std::min<Index>(bones - 1, static_cast<Index>(std::floor(z / bone_length)));
    per_vertex[v] = {{bone, 1.0}};
    for (Index k = 1; k < bones; ++k) {
      const double zk = k * bone_length;
      if (std::abs(z - zk) < half) {
        const double t = (z - (zk - half)) / (2.0 * half);
        per_vertex[v] = {{k - 1, 1.0 - t}, {k, t}};
      }
    }
  }
  out.mesh.skin = make_skin_weights(per_vertex);
  Animation bend;
  bend.name = "bend";
  for (Index k = 1; k < bones; ++k) {
    AnimationChannel c;
    c.joint = k;
    c.path = AnimationChannel::Path::Rotation;
    for (Index f = 0; f < frames; ++f) {
      const double angle = frames > 1 ? max_angle_deg * std::numbers::pi / 180.0 * f / (frames - 1) : 0.0;
      const Quat q(Eigen::AngleAxisd(angle, Vec3::UnitX()));
      c.times.push_back(f / 24.0);
      c.values.emplace_back(q.x(), q.y(), q.z(), q.w());
    }
    bend.channels.push_back(std::move(c));
  }
  out.rig.animations.push_back(std::move(bend));
  return out;
}

}  // namespace quadlod
