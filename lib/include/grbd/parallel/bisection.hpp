#pragma once
/// \file
/// \brief Recursive coordinate bisection (chapter 8): a tree of boxes, one leaf per process, each
/// cut placed where it halves the weight of the bodies in its box — the balance a tensor grid
/// cannot give when the load is uneven in more than one direction at once.

#include <array>
#include <span>
#include <vector>

#include "grbd/core/communicator.hpp"
#include "grbd/parallel/decomposition.hpp"

namespace grbd::parallel {

/// A domain cut into `size()` boxes by a binary tree of axis-aligned cuts. A node holds the
/// processes [r₀, r₁) and a box; it is cut along the longest side of its box into a lower part for
/// the first ⌊n/2⌋ of its n processes and an upper part for the others, and each part is cut again
/// until it holds one process. Rank r owns the positions of its leaf, [lo, hi) along each axis
/// (a position on a cut belongs to the upper side); a position outside the domain belongs to the
/// leaf reached by the same descent, i.e. the nearest leaf along each non-periodic axis, and along
/// a periodic axis it is wrapped into the domain first. Every process builds the same tree from the
/// same numbers and so agrees on every owner.
class BisectionTree {
 public:
  /// The tree of `processes` leaves whose cuts split the volume of each box in proportion to its
  /// processes (the even tree). Throws InvalidArgument for an empty or non-finite domain or fewer
  /// than one process.
  BisectionTree(const Box& domain, int processes,
                const std::array<bool, 3>& periodic = {false, false, false});

  /// The tree whose every cut splits the weight of the bodies' centres in its box in proportion
  /// to its processes (⌊n/2⌋ : ⌈n/2⌉), found level by level by bisection on sums over every
  /// process (collective: each passes its own bodies; centres wrapped along the periodic axes, a
  /// body outside the domain counted in the box that owns it). Every process gets the same tree,
  /// whatever the spread of the bodies over the processes. A box without weight is cut as in the
  /// even tree. Throws InvalidArgument for spans of different lengths or a negative or
  /// non-finite weight (on the process that has it).
  static BisectionTree balanced(const Communicator& comm, const Box& domain, int processes,
                                const std::array<bool, 3>& periodic,
                                std::span<const Vector3> centres, std::span<const double> weights);

  /// Number of leaves (= processes).
  int size() const { return static_cast<int>(leaves_.size()); }
  /// The whole domain.
  const Box& domain() const { return domain_; }
  /// Whether each axis is periodic.
  const std::array<bool, 3>& periodic() const { return periodic_; }
  /// The box of a rank's leaf.
  const Box& subdomain(int rank) const;
  /// The region whose bodies a rank owns: its leaf, extended to ±∞ along each non-periodic axis
  /// where it ends the domain.
  Box owned_region(int rank) const;
  /// The rank that owns a position (descent through the cuts of the wrapped position).
  int owner_of(const Vector3& position) const;
  /// The ranks whose leaf, or a periodic image of it, lies within `reach` of the leaf of `rank`,
  /// sorted, each once; `rank` itself only through a periodic image. O(P) per call.
  std::vector<int> neighbours(int rank, double reach) const;
  /// A position moved into the domain along the periodic axes.
  Vector3 wrap(const Vector3& position) const;

 private:
  struct Node {
    int first = 0, count = 1;  // the processes [first, first + count)
    int axis = -1;             // −1: a leaf
    double cut = 0.0;          // lower part: coordinate < cut
    int lower = -1, upper = -1;
  };
  BisectionTree(const Box& domain, const std::array<bool, 3>& periodic);
  // The leaves' boxes, from the nodes' cuts.
  void make_leaves();
  Box domain_;
  std::array<bool, 3> periodic_;
  std::vector<Node> nodes_;  // nodes_[0] is the root
  std::vector<Box> leaves_;  // by rank
};

}  // namespace grbd::parallel
