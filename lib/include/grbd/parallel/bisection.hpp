#pragma once
/// \file
/// \brief Recursive coordinate bisection (chapter 8): a tree of boxes, one leaf per process, each
/// cut placed where it halves the weight of the bodies in its box — the balance a tensor grid
/// cannot give when the load is uneven in more than one direction at once.

#include <array>
#include <memory>
#include <span>
#include <vector>

#include "grbd/core/communicator.hpp"
#include "grbd/parallel/partition.hpp"

namespace grbd::parallel {

/// A domain cut into `size()` boxes by a binary tree of axis-aligned cuts. A node holds the
/// processes [r₀, r₁) and a box; it is cut along the longest side of its box into a lower part for
/// the first ⌊n/2⌋ of its n processes and an upper part for the others, and each part is cut again
/// until it holds one process. Rank r owns the positions of its leaf, [lo, hi) along each axis
/// (a position on a cut belongs to the upper side); a position outside the domain belongs to the
/// leaf reached by the same descent, i.e. the nearest leaf along each non-periodic axis, and along
/// a periodic axis it is wrapped into the domain first. Every process builds the same tree from the
/// same numbers and so agrees on every owner.
class BisectionTree final : public Partition {
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

  /// A copy.
  std::unique_ptr<Partition> clone() const override {
    return std::make_unique<BisectionTree>(*this);
  }
  /// The balanced() tree of the bodies with as many leaves.
  std::vector<double> cuts() const override;
  std::unique_ptr<Partition> with_cuts(std::span<const double> cuts) const override;
  std::unique_ptr<Partition> rebalanced(const Communicator& comm, std::span<const Vector3> centres,
                                        std::span<const double> weights) const override;

  /// Number of leaves (= processes).
  int size() const override { return static_cast<int>(leaves_.size()); }
  /// The box of a rank's leaf.
  Box subdomain(int rank) const override;
  /// The rank that owns a position (descent through the cuts of the wrapped position).
  int owner_of(const Vector3& position) const override;

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
  std::vector<Node> nodes_;  // nodes_[0] is the root
  std::vector<Box> leaves_;  // by rank
};

}  // namespace grbd::parallel
