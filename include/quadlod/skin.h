// quadlod — skeletons, animations and linear blend skinning (issue 24).
//
// The per-vertex weights live in the mesh (PolyMesh::skin, include/quadlod/mesh.h); this header
// holds what a skinned file carries besides the mesh — the skeleton and its animations (`Rig`) —
// and the operations on them:
//   * sampling an animation at a time into a local pose (per joint translation, rotation, scale);
//   * the global joint matrices of a pose and the skinning matrices G_j · B_j⁻¹;
//   * posing a mesh by linear blend skinning, p' = Σ_j w_j (G_j B_j⁻¹) p;
//   * moving weights from a skinned mesh onto another surface by projection (the reduction's
//     output, a peer's output, the quad OBJ of a triangulated glTF): docs/skinning.md says why
//     projection and not attribute-aware quadrics.
// Conventions follow glTF 2.0 (§3.7.3 "Skins", §3.11 "Animations"): local transform = T · R · S,
// quaternions (x, y, z, w) normalised, positions of the skinned mesh in the skeleton's bind space,
// times in seconds.
#pragma once

#include "quadlod/mesh.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace quadlod {

using Mat4 = Eigen::Matrix4d;
using Quat = Eigen::Quaterniond;

/// A joint's local transform relative to its parent: matrix = T · R · S.
struct JointTransform {
  Vec3 translation = Vec3::Zero();
  Quat rotation = Quat::Identity();
  Vec3 scale = Vec3::Ones();
  Mat4 matrix() const;
};

struct Joint {
  std::string name;
  Index parent = kInvalidIndex;  ///< index into Skeleton::joints; kInvalidIndex for a root
  JointTransform rest;           ///< local transform when no animation drives it
  Mat4 inverse_bind = Mat4::Identity();  ///< B⁻¹: bind space → the joint's space at the bind pose
};

/// Joints with their hierarchy. Parents may come in any order but the hierarchy is acyclic.
struct Skeleton {
  std::vector<Joint> joints;
  /// Global transform of whatever the roots hang from (glTF: the nodes above the top joint).
  Mat4 root_transform = Mat4::Identity();
  Index num_joints() const { return static_cast<Index>(joints.size()); }
  /// "" when every parent is a valid joint or kInvalidIndex, there is no cycle and every matrix
  /// is finite; else the first problem, naming the joint.
  std::string check() const;
};

/// One animated property of one joint (glTF channel + sampler). Keys are sorted by time;
/// `values` are xyz (w unused) for translation and scale, xyzw for rotation.
struct AnimationChannel {
  enum class Path { Translation, Rotation, Scale };
  enum class Interpolation { Step, Linear };  ///< glTF CUBICSPLINE is read as Linear on its values
  Index joint = 0;
  Path path = Path::Rotation;
  Interpolation interpolation = Interpolation::Linear;
  std::vector<double> times;
  std::vector<Eigen::Vector4d> values;
};

struct Animation {
  std::string name;
  std::vector<AnimationChannel> channels;
  double start_time() const;  ///< earliest key (0 when there is none)
  double end_time() const;    ///< latest key
  /// The animation's frames: the sorted union of all key times, times closer than `merge` seconds
  /// counted once. A baked export (Blender's "force sampling") keys every frame, so these are
  /// exactly its frames.
  std::vector<double> frame_times(double merge = 1e-4) const;
};

/// Everything of a skinned asset besides the mesh and its weights.
struct Rig {
  Skeleton skeleton;
  std::vector<Animation> animations;
  bool empty() const { return skeleton.joints.empty(); }
};

/// A skinned mesh with its rig, as the glTF reader returns it and the generators make it.
struct SkinnedMesh {
  PolyMesh mesh;  ///< mesh.skin indexes rig.skeleton.joints
  Rig rig;
};

// --- poses -------------------------------------------------------------------------------------

/// The local pose of every joint when nothing is animated (their `rest` transforms).
std::vector<JointTransform> rest_pose(const Skeleton& skeleton);

/// Poses that need no animation, for deformation-sensitive reduction of any rig (docs/skinning.md,
/// "Poses"): pose k turns every joint by `angle_deg` about axis k of `count` axes spread evenly over
/// the sphere (a Fibonacci spiral) in the joint's own frame, on top of its rest rotation. The same
/// skeleton, count and angle always give the same poses.
std::vector<std::vector<JointTransform>> range_of_motion_poses(const Skeleton& skeleton, Index count,
                                                               double angle_deg = 30.0);

/// The local pose at `time` (seconds): each channel interpolated (linear: lerp for translation and
/// scale, shortest-arc slerp for rotation; step: the last key at or before `time`), clamped to
/// the first / last key outside its range; joints and properties no channel drives keep `rest`.
std::vector<JointTransform> sample_pose(const Skeleton& skeleton, const Animation& animation, double time);

/// Global matrices of a local pose: G_j = G_parent · L_j, roots under skeleton.root_transform.
/// Precondition: skeleton.check() is empty and local.size() == num_joints().
std::vector<Mat4> global_joint_matrices(const Skeleton& skeleton, const std::vector<JointTransform>& local);

/// Skinning matrices G_j · B_j⁻¹ (glTF's joint matrices): identity for every joint when the pose
/// is the bind pose.
std::vector<Mat4> skinning_matrices(const Skeleton& skeleton, const std::vector<Mat4>& globals);

/// Linear blend skinning: each vertex v with influences (j, w) moves to Σ w · M_j · v; a vertex
/// without influence keeps its position. Faces, UVs and tags are copied; per-corner normals are
/// dropped (the pose would need them re-derived and the metrics do not use them); `skin` is
/// copied. Precondition: every influence's joint < matrices.size(); `mesh.skin` not empty.
PolyMesh pose_mesh(const PolyMesh& mesh, const std::vector<Mat4>& matrices);

// --- weights -------------------------------------------------------------------------------------

/// One influence of a joint on a vertex.
struct Influence {
  Index joint = 0;
  double weight = 0.0;
};

/// Canonical form of one vertex's influences (mesh.h, SkinWeights): sums duplicate joints, drops
/// weights <= min_weight (a fraction of the largest), keeps the `max_influences` largest (0 = all),
/// sorts by decreasing weight (ties: increasing joint) and renormalises to sum 1. Empty when
/// nothing positive is left.
std::vector<Influence> canonical_influences(std::vector<Influence> influences, Index max_influences = 0,
                                            double min_weight = 0.0);

/// SkinWeights from per-vertex lists (each put in canonical form with the same arguments).
SkinWeights make_skin_weights(const std::vector<std::vector<Influence>>& per_vertex, Index max_influences = 0,
                              double min_weight = 0.0);

/// The influences of vertex v.
std::vector<Influence> influences_of(const SkinWeights& skin, Index v);

/// Half the L1 distance between two vertices' weight vectors (total variation): 0 when they
/// follow the same joints equally, 1 when they share no joint. In [0, 1].
double weight_distance(const SkinWeights& a, Index va, const SkinWeights& b, Index vb);

struct SkinTransferParams {
  /// Most influences per target vertex; 0 = the source's largest count (the issue's "at most the
  /// input's influences per vertex").
  Index max_influences = 0;
  /// Interpolated weights below this fraction of the vertex's largest are dropped before the
  /// renormalisation (they only arise from blending three corners, and glTF viewers cap at 4).
  double min_weight = 1e-3;
  /// The projection takes the closest source triangle facing the same way as the target vertex
  /// (normals within this angle), so a vertex near two surfaces — a leg against the body, the
  /// lips — takes the weights of its own side; if none within `max_side_distance`, the closest.
  double max_normal_angle_deg = 90.0;
  /// How far (fraction of the source's bounding-box diagonal) the same-side triangle may be.
  double max_side_distance = 0.05;
  /// Parts (connected pieces) keep to their part: every target part is matched to the source
  /// part most of its vertices lie closest to (by area), and its vertices are projected onto that
  /// part only. Without it, the ram's head vertices at the rim of an eye socket took the eyeball's
  /// weights (45 faces of quadlod's LOD at 0.2, 38 of Single's, joined an eye vertex to head
  /// vertices; the input has none), and in the walk those faces stretched as the eyes turned:
  /// both LODs' worst per-frame distance, 0.059 against 0.024–0.037 at the bind pose
  /// (docs/skinning.md). The candidates are the source parts nearest to at least
  /// `min_part_share` of the target part's vertices (by area); the part keeps to the candidate
  /// its vertices lie closest to (area-weighted mean squared distance: the ram's eyeball is
  /// overlapped by two eyelid shells, and half its vertices lie nearest to a lid), unless one of
  /// its vertices lies farther from it than `max_part_distance_edges` of the part's mean edge
  /// length (a part a reducer joined from two), and then it projects onto every part.
  bool keep_parts = true;
  double min_part_share = 0.2;
  double max_part_distance_edges = 1.0;
};

struct SkinTransferResult {
  SkinWeights skin;             ///< one entry per target vertex
  Index same_side = 0;          ///< vertices projected onto a triangle facing their way
  Index nearest_only = 0;       ///< vertices that took the plain closest triangle (of their part)
  Index parts = 0;              ///< connected parts of the target
  Index parts_matched = 0;      ///< of those, projected onto one source part (keep_parts)
  double max_distance = 0.0;    ///< largest projection distance (source units)
  double mean_distance = 0.0;
};

/// Weights for every vertex of `target` by projection onto the surface of `source` (fan
/// triangulation): the closest point's triangle blends its three corners' influences by the
/// barycentric coordinates of that point, in canonical form with params.max_influences.
/// Precondition: source.skin is not empty and both meshes pass check_layout(); a target vertex
/// used by no face uses the plain closest point. Deterministic.
SkinTransferResult transfer_skin_weights(const PolyMesh& source, const PolyMesh& target,
                                         const SkinTransferParams& params = {});

}  // namespace quadlod
