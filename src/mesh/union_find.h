// Disjoint-set forest with path halving and union by size. Used for face components, vertex
// fans, and the cluster collapse of §3.3.2 (vertices joined by collapsed edges).
#pragma once

#include "quadlod/mesh.h"

#include <numeric>
#include <utility>
#include <vector>

namespace quadlod {

class UnionFind {
 public:
  explicit UnionFind(Index n) : parent_(n), size_(n, 1) {
    std::iota(parent_.begin(), parent_.end(), Index{0});
  }
  Index find(Index x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  /// Joins the sets of a and b; returns the new root, or kInvalidIndex if already joined.
  Index unite(Index a, Index b) {
    a = find(a);
    b = find(b);
    if (a == b) return kInvalidIndex;
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
    return a;
  }
  Index set_size(Index x) { return size_[find(x)]; }
  /// A label 0..count-1 per element, numbering the sets in order of their first element.
  std::vector<Index> dense_labels(Index& count) {
    std::vector<Index> label(parent_.size()), of_root(parent_.size(), kInvalidIndex);
    count = 0;
    for (Index x = 0; x < size(); ++x) {
      const Index r = find(x);
      if (of_root[r] == kInvalidIndex) of_root[r] = count++;
      label[x] = of_root[r];
    }
    return label;
  }
  Index size() const { return static_cast<Index>(parent_.size()); }
  /// Makes x a singleton again. Only valid when every member of x's set is reset in the same
  /// sweep (no other element may still point at one of them): how a set is split and rebuilt.
  void reset(Index x) {
    parent_[x] = x;
    size_[x] = 1;
  }

 private:
  std::vector<Index> parent_;
  std::vector<Index> size_;
};

}  // namespace quadlod
