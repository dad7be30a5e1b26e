// Module-internal: union-find over labels 0, 1, 2, ... in which a set's root is its smallest label, so
// that the roots in label order are the sets in the order of their first label (the labellings of
// dark_components.cc and blob_window.cc give labels in raster order).
#pragma once

#include <utility>
#include <vector>

namespace selfcal::tracking::internal {

class DisjointSets {
 public:
  void Clear() { parent_.clear(); }
  size_t size() const { return parent_.size(); }

  // A new set of its own; returns its label.
  int Add() {
    parent_.push_back(static_cast<int>(parent_.size()));
    return parent_.back();
  }

  int Find(int x) {
    while (parent_[static_cast<size_t>(x)] != x) {
      parent_[static_cast<size_t>(x)] = parent_[static_cast<size_t>(parent_[static_cast<size_t>(x)])];  // halving
      x = parent_[static_cast<size_t>(x)];
    }
    return x;
  }

  // Joins the sets of a and b: {the joined set's root, the root it absorbed, or -1 if a and b were one set}.
  std::pair<int, int> Union(int a, int b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return {a, -1};
    if (a < b) std::swap(a, b);
    parent_[static_cast<size_t>(a)] = b;
    return {b, a};
  }

 private:
  std::vector<int> parent_;
};

}  // namespace selfcal::tracking::internal
