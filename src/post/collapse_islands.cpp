// UV islands and parts of the cluster collapse (issue 7; docs/attributes.md, "Islands neither
// vanish nor split"; issue 32, "Parts"): which islands and parts Collapser protects, the islands'
// edge-connected components before and after the collapse, and the checks that refuse the
// clusters that would make an island vanish or fall apart, or a part vanish. The class:
// collapser.h.
#include "mesh/union_find.h"
#include "post/collapser.h"

#include <algorithm>
#include <numeric>

namespace quadlod::collapse_detail {

// Islands the collapse keeps whole (docs/attributes.md, "Islands neither vanish nor split").
// Seams are strict, so no cluster joins two islands, but nothing else stopped a cluster from
// taking an island's last faces — a closed part without any feature line (an eyeball of
// flightgear_head_amelia, 112 faces, one island) or a lone n-gon decal whose boundary is one
// feature line (flightgear_cg57_cruiser_hd) collapsed whole — or from cutting it in two: a thin
// tube (cg57, 4 quads around) whose two middle rings each collapse to a point leaves two cones
// and drops the faces between, with no new boundary and no non-manifold vertex. Per-face layouts
// are exempt: they must lose islands to be reduced at all.
void Collapser::protect_islands() {
  if (params_.min_kept_island_area < 0.0) return;
  IslandAreas k = island_areas(mesh_, conn_, params_.face_island_area, params_.features.per_face_layout_fraction);
  if (k.exempt) return;
  const Index n = k.islands.num_islands;
  island_keep_.assign(n, 0);
  island_crossable_.assign(n, 0);
  // An island its lines may cross shrinks between them and may vanish: kept whole, it would
  // only fall apart where they meet (issue 32).
  const double keep = std::max(params_.min_kept_island_area, params_.crossing_island_area);
  for (Index i = 0; i < n; ++i) {
    island_keep_[i] = k.area[i] > 0.0 && k.area[i] >= keep;
    island_crossable_[i] = k.area[i] > 0.0 && k.area[i] < params_.crossing_island_area;
  }
  face_island_ = std::move(k.islands.face_island);
  island_begin_.assign(n + 1, 0);
  for (Index f = 0; f < nf_; ++f)
    if (face_island_[f] != kInvalidIndex) ++island_begin_[face_island_[f] + 1];
  for (Index i = 0; i < n; ++i) island_begin_[i + 1] += island_begin_[i];
  island_faces_.resize(island_begin_[n]);
  std::vector<Index> fill(island_begin_.begin(), island_begin_.end() - 1);
  for (Index f = 0; f < nf_; ++f)
    if (face_island_[f] != kInvalidIndex) island_faces_[fill[face_island_[f]]++] = f;
  // Every island is one edge-connected piece in the input: find_uv_islands joins faces across
  // the connectivity's edges, and an edge is a vertex pair, so two faces it joins share a side.
  // A split is therefore any island the collapse leaves in more than one piece.
  island_token_.assign(n, 0);
  root_component_.assign(nv_, kInvalidIndex);
  root_component_token_.assign(nv_, 0);
}

// Sorts sides_ by (a, b, piece), the order the blame of check_islands follows. The whole-mesh
// island of a UV grid has four sides per face, and a comparison sort of them was the largest
// cost of a pass on a 1M-face grid (issue 20), so a large set is bucketed by a (a counting sort
// over the roots, which are vertex ids) and each bucket, a vertex's few sides, sorted in place.
// The order is the same either way.
void Collapser::sort_sides() {
  auto less = [](const IslandSide& x, const IslandSide& y) {
    return x.a != y.a ? x.a < y.a : x.b != y.b ? x.b < y.b : x.piece < y.piece;
  };
  // Bucketing costs O(vertices): only where the sides are as many as a quarter of them (the
  // output is the same; this is speed only).
  if (sides_.size() * 4 < std::size_t(nv_)) {
    std::sort(sides_.begin(), sides_.end(), less);
    return;
  }
  side_bucket_.assign(std::size_t(nv_) + 1, 0);
  for (const IslandSide& s : sides_) ++side_bucket_[s.a + 1];
  for (Index v = 0; v < nv_; ++v) side_bucket_[v + 1] += side_bucket_[v];
  sides_sorted_.resize(sides_.size());
  for (const IslandSide& s : sides_) sides_sorted_[side_bucket_[s.a]++] = s;
  // side_bucket_[v] is now the end of bucket v, the start of bucket v + 1.
  Index begin = 0;
  for (Index v = 0; v < nv_; ++v) {
    const Index end = side_bucket_[v];
    if (end - begin > 1) std::sort(sides_sorted_.begin() + begin, sides_sorted_.begin() + end, less);
    begin = end;
  }
  sides_.swap(sides_sorted_);
}

// Edge-connected components of island i's surviving pieces, their corners at the output
// vertices (cluster roots). piece_component gets each surviving piece's component, in the order
// of island_faces_ and pieces.
Index Collapser::island_components(Index i, std::vector<Index>& piece_component) {
  std::vector<IslandSide>& sides = sides_;
  sides.clear();
  fan_root_ = kInvalidIndex;  // fan_ may have been rebuilt since the last call
  Index pieces = 0;
  for (Index k = island_begin_[i]; k < island_begin_[i + 1]; ++k) {
    const Index f = island_faces_[k];
    Index off = piece_base(f);
    for (Index p = 0; p < piece_count_[f]; ++p) {
      const Index len = piece_buf_[off];
      for (Index j = 0; j < len; ++j) {
        const Index a = root_of_corner(piece_buf_[off + 1 + j]), b = root_of_corner(piece_buf_[off + 1 + (j + 1) % len]);
        sides.push_back({std::min(a, b), std::max(a, b), pieces});
      }
      ++pieces;
      off += len + 1;
    }
  }
  sort_sides();
  UnionFind uf(pieces);
  {
    // find_uv_islands joins faces only across edges with exactly two faces, so an output side
    // joins two pieces only if no other output face lies on it. A collapse can fold an island
    // onto itself or onto a coincident sheet (flightgear_cg57_cruiser_hd at 0.6: one side with
    // three faces of a 24-quad island and two of a twin sheet), and the island is then cut in
    // two there although its UVs agree across the side. Such sides are kept for the blame.
    unjoined_sides_.clear();
    for (std::size_t k = 0; k < sides.size();) {
      std::size_t end = k + 1;
      while (end < sides.size() && sides[end].a == sides[k].a && sides[end].b == sides[k].b) ++end;
      if (end - k == 2 && pieces_on_side(sides[k].a, sides[k].b) == 2)
        uf.unite(sides[k].piece, sides[k + 1].piece);
      else if (end - k >= 2)
        for (std::size_t j = k; j < end; ++j) unjoined_sides_.push_back({sides[j].a, sides[j].b, sides[j].piece});
      k = end;
    }
  }
  Index components = 0;
  std::vector<Index> id(pieces, kInvalidIndex);
  piece_component.assign(pieces, kInvalidIndex);
  for (Index p = 0; p < pieces; ++p) {
    Index& c = id[uf.find(p)];
    if (c == kInvalidIndex) c = components++;
    piece_component[p] = c;
  }
  return components;
}

// Output pieces of every input face, the island's or not, with a side between roots a and b:
// the sides next to a in its fan. Rebuilds fan_: called from check_islands, after every fan of
// the round is done.
Index Collapser::pieces_on_side(Index a, Index b) {
  // Sides arrive sorted by a, so consecutive calls share a's fan.
  if (fan_root_ != a) {
    gather_fan(a);
    fan_root_ = a;
  }
  Index count = 0;
  for (const auto& e : fan_) {
    const Index* cs = piece_buf_.data() + e.first;
    count += root_of_corner(cs[(e.pos + 1) % e.len]) == b;
    count += root_of_corner(cs[(e.pos + e.len - 1) % e.len]) == b;
  }
  return count;
}

// Islands of dirty faces (refusal `island`):
//   * vanished: an island of at least min_kept_island_area without any surviving face. The
//     clusters at the corners of its largest face are refused (split, then dissolved), until that
//     face survives; refusing every cluster on the island would undo far more than needed.
//   * split: its surviving pieces fall into more than one edge-connected component (every island
//     is one in the input; protect_islands). The clusters at the corners of the dropped faces between two components are
//     refused — the ring of a tube collapsed to a point on each side of a dropped band.
// With skip_checked, the islands the previous call checked are left out: the final check of a
// round that refused nothing sees them as that call did.
void Collapser::check_islands(const std::vector<Index>& dirty, bool skip_checked) {
  if (!skip_checked) ++island_tok_;
  std::vector<Index> piece_component;
  for (Index f : dirty) {
    const Index i = face_island_[f];
    if (i == kInvalidIndex || island_token_[i] == island_tok_) continue;
    island_token_[i] = island_tok_;
    const Index* begin = island_faces_.data() + island_begin_[i];
    const Index* end = island_faces_.data() + island_begin_[i + 1];
    if (!std::any_of(begin, end, [&](Index g) { return piece_count_[g] > 0; })) {
      if (!island_keep_[i]) continue;
      const Index* largest = std::max_element(begin, end, [&](Index a, Index b) { return face_area_[a] < face_area_[b]; });
      for (Index c = mesh_.face_begin(*largest); c < mesh_.face_end(*largest); ++c)
        blame(root_of_corner(c), CollapseRefusal::Island);
      continue;
    }
    const Index components = island_components(i, piece_component);
    if (components <= 1) continue;
    // The component of every root on a surviving piece (and the roots that pieces of two
    // components share), then the dropped faces touching two.
    ++component_tok_;
    pinch_roots_.clear();
    Index p = 0;
    for (const Index* g = begin; g != end; ++g) {
      Index off = piece_base(*g);
      for (Index q = 0; q < piece_count_[*g]; ++q, ++p) {
        const Index len = piece_buf_[off];
        for (Index j = 0; j < len; ++j) {
          const Index r = root_of_corner(piece_buf_[off + 1 + j]);
          if (root_component_token_[r] != component_tok_) {
            root_component_token_[r] = component_tok_;
            root_component_[r] = piece_component[p];
          } else if (root_component_[r] != piece_component[p]) {
            pinch_roots_.push_back(r);
          }
        }
        off += len + 1;
      }
    }
    bool blamed_any = false;
    // A side with more than two faces that would join two components if it had only the
    // island's two: refuse the clusters at its ends, which made it (the island's own pieces
    // folded onto one side, or a coincident sheet collapsed onto it).
    for (std::size_t k = 0; k < unjoined_sides_.size();) {
      std::size_t side_end = k + 1;
      bool two = false;
      while (side_end < unjoined_sides_.size() && unjoined_sides_[side_end].a == unjoined_sides_[k].a &&
             unjoined_sides_[side_end].b == unjoined_sides_[k].b) {
        two = two || piece_component[unjoined_sides_[side_end].piece] != piece_component[unjoined_sides_[k].piece];
        ++side_end;
      }
      const Index a = unjoined_sides_[k].a, b = unjoined_sides_[k].b;
      if (two && (cluster_size(a) > 1 || cluster_size(b) > 1)) {
        blame(a, CollapseRefusal::Island);
        blame(b, CollapseRefusal::Island);
        blamed_any = true;
      }
      k = side_end;
    }
    for (const Index* g = begin; g != end; ++g) {
      if (piece_count_[*g] > 0) continue;
      Index first = kInvalidIndex;
      bool two = false;
      for (Index c = mesh_.face_begin(*g); c < mesh_.face_end(*g); ++c) {
        const Index r = root_of_corner(c);
        if (root_component_token_[r] != component_tok_) continue;
        if (first == kInvalidIndex) first = root_component_[r];
        else two = two || root_component_[r] != first;
      }
      if (!two) continue;
      blamed_any = true;
      for (Index c = mesh_.face_begin(*g); c < mesh_.face_end(*g); ++c) blame(root_of_corner(c), CollapseRefusal::Island);
    }
    if (!blamed_any)  // no dropped face between two pieces: refuse every cluster on a dropped face
      for (const Index* g = begin; g != end; ++g)
        if (piece_count_[*g] == 0)
          for (Index c = mesh_.face_begin(*g); c < mesh_.face_end(*g); ++c) {
            blame(root_of_corner(c), CollapseRefusal::Island);
            blamed_any = true;
          }
    // No face dropped at all: the pieces meet at a point only, a cluster that pinched the island
    // where its two sides merged (a strip whose lines crossed at one rung, issue 32: cg57 at
    // 0.6). Refuse the clusters that pieces of two components share.
    if (!blamed_any)
      for (Index r : pinch_roots_) blame(r, CollapseRefusal::Island);
  }
}

// Parts (connected components, faces joined through shared vertices, as eval counts them) keep
// a face unless their area is below max_vanishing_part_area: a part that vanishes takes its
// whole extent out of the output, and is the Hausdorff point wherever it is larger than the
// error elsewhere (issue 32: flightgear_cessna337 at 0.4, a 120-face part 0.017 long, once its
// UV island was allowed to vanish).
void Collapser::protect_parts() {
  UnionFind uf(nv_);
  for (Index f = 0; f < nf_; ++f) {
    const Index first = mesh_.corner_vertex[mesh_.face_begin(f)];
    for (Index c = mesh_.face_begin(f) + 1; c < mesh_.face_end(f); ++c) uf.unite(first, mesh_.corner_vertex[c]);
  }
  std::vector<Index> part_of_root(nv_, kInvalidIndex);
  face_part_.assign(nf_, kInvalidIndex);
  Index n = 0;
  for (Index f = 0; f < nf_; ++f) {
    Index& id = part_of_root[uf.find(mesh_.corner_vertex[mesh_.face_begin(f)])];
    if (id == kInvalidIndex) id = n++;
    face_part_[f] = id;
  }
  std::vector<double> area(n, 0.0);
  for (Index f = 0; f < nf_; ++f) area[face_part_[f]] += face_area_[f];
  part_keep_.assign(n, 0);
  bool any = false;
  for (Index i = 0; i < n; ++i) {
    part_keep_[i] = !(area[i] < params_.max_vanishing_part_area);
    any = any || part_keep_[i];
  }
  if (!any) {
    face_part_.clear();
    return;
  }
  part_begin_.assign(n + 1, 0);
  for (Index f = 0; f < nf_; ++f) ++part_begin_[face_part_[f] + 1];
  for (Index i = 0; i < n; ++i) part_begin_[i + 1] += part_begin_[i];
  part_faces_.resize(nf_);
  std::vector<Index> fill(part_begin_.begin(), part_begin_.end() - 1);
  for (Index f = 0; f < nf_; ++f) part_faces_[fill[face_part_[f]]++] = f;
  part_token_.assign(n, 0);
}

// Refusal `part`: a part that must keep a face has none left among `faces`' parts. The clusters
// at the corners of its largest face are refused (split, then dissolved) until that face
// survives, as for an island.
void Collapser::check_parts(const std::vector<Index>& faces) {
  ++part_tok_;
  for (Index f : faces) {
    const Index i = face_part_[f];
    if (part_token_[i] == part_tok_) continue;
    part_token_[i] = part_tok_;
    if (!part_keep_[i]) continue;
    const Index* begin = part_faces_.data() + part_begin_[i];
    const Index* end = part_faces_.data() + part_begin_[i + 1];
    if (std::any_of(begin, end, [&](Index g) { return piece_count_[g] > 0; })) continue;
    const Index* largest = std::max_element(begin, end, [&](Index a, Index b) { return face_area_[a] < face_area_[b]; });
    for (Index c = mesh_.face_begin(*largest); c < mesh_.face_end(*largest); ++c) blame(root_of_corner(c), CollapseRefusal::Part);
  }
}

const std::vector<Index>& Collapser::all_faces_list() {
  if (all_faces_.size() != nf_) {
    all_faces_.resize(nf_);
    std::iota(all_faces_.begin(), all_faces_.end(), Index{0});
  }
  return all_faces_;
}

}  // namespace quadlod::collapse_detail
