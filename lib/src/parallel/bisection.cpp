/// \file
/// \brief Recursive coordinate bisection: the even tree and the tree balanced by weight.

#include "grbd/parallel/bisection.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/parallel/balance.hpp"

namespace grbd::parallel {

namespace {

// The longest side of a box (ties: the first axis).
int longest_axis(const Box& box) {
  const Vector3 size = box.sizes();
  int axis = 0;
  for (int d = 1; d < 3; ++d) {
    if (size[d] > size[axis]) axis = d;
  }
  return axis;
}

// A cut strictly inside [lo, hi] along its axis, so that neither part is empty of space.
double inside(double cut, double lo, double hi) {
  const double gap = 1e-9 * (hi - lo);
  return std::clamp(cut, lo + gap, hi - gap);
}

}  // namespace

BisectionTree::BisectionTree(const Box& domain, const std::array<bool, 3>& periodic)
    : Partition(domain, periodic, "BisectionTree") {}

BisectionTree::BisectionTree(const Box& domain, int processes, const std::array<bool, 3>& periodic)
    : BisectionTree(domain, periodic) {
  if (processes < 1) {
    throw InvalidArgument("BisectionTree: expected at least one process, found " +
                          std::to_string(processes));
  }
  // Breadth first: each node cut by volume in proportion to its processes.
  nodes_.push_back({0, processes});
  std::vector<Box> boxes{domain};
  for (std::size_t k = 0; k < nodes_.size(); ++k) {
    if (nodes_[k].count == 1) continue;
    const Box box = boxes[k];
    Node node = nodes_[k];
    node.axis = longest_axis(box);
    const int low = node.count / 2;
    const double lo = box.min()[node.axis], hi = box.max()[node.axis];
    node.cut = inside(lo + (hi - lo) * low / node.count, lo, hi);
    node.lower = static_cast<int>(nodes_.size());
    node.upper = node.lower + 1;
    Box lower = box, upper = box;
    lower.max()[node.axis] = node.cut;
    upper.min()[node.axis] = node.cut;
    nodes_[k] = node;
    nodes_.push_back({node.first, low});
    nodes_.push_back({node.first + low, node.count - low});
    boxes.push_back(lower);
    boxes.push_back(upper);
  }
  make_leaves();
}

// [bisection tree]
BisectionTree BisectionTree::balanced(const Communicator& comm, const Box& domain, int processes,
                                      const std::array<bool, 3>& periodic,
                                      std::span<const Vector3> centres,
                                      std::span<const double> weights) {
  require_weights(centres, weights, "BisectionTree::balanced");
  BisectionTree tree(domain, processes, periodic);  // checks; the even cuts where no weight is
  // The bodies' wrapped centres, and the node each has reached (all start at the root).
  std::vector<Vector3> at(centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) at[i] = tree.wrap(centres[i]);
  std::vector<int> node_of(centres.size(), 0);
  // The nodes of one depth are cut together: [first, last) of tree.nodes_, in breadth-first
  // order; their children are the next depth.
  std::vector<Box> boxes{domain};
  std::size_t first = 0, last = 1;
  std::vector<Node>& nodes = tree.nodes_;
  while (first < last) {
    // The nodes of this depth that are cut, their boxes, and this process's bodies in each,
    // sorted along the node's axis with prefix sums of their weights.
    std::vector<std::size_t> cut;
    for (std::size_t k = first; k < last; ++k) {
      if (nodes[k].count == 1) continue;
      cut.push_back(k);
      nodes[k].axis = longest_axis(boxes[k]);  // of the box the cuts above have left
    }
    std::vector<std::vector<std::pair<double, double>>> along(cut.size());
    std::vector<std::size_t> slot(nodes.size(), 0);
    for (std::size_t c = 0; c < cut.size(); ++c) slot[cut[c]] = c;
    for (std::size_t i = 0; i < at.size(); ++i) {
      const auto k = static_cast<std::size_t>(node_of[i]);
      if (nodes[k].count == 1) continue;
      along[slot[k]].emplace_back(at[i][nodes[k].axis], weights[i]);
    }
    std::vector<std::vector<double>> sorted(cut.size()), prefix(cut.size());
    std::vector<double> total(cut.size(), 0.0);
    for (std::size_t c = 0; c < cut.size(); ++c) {
      std::sort(along[c].begin(), along[c].end());
      prefix[c].assign(along[c].size() + 1, 0.0);
      for (std::size_t j = 0; j < along[c].size(); ++j) {
        sorted[c].push_back(along[c][j].first);
        prefix[c][j + 1] = prefix[c][j] + along[c][j].second;
      }
      total[c] = prefix[c].back();
    }
    comm.sum(total);
    // Bisection of every cut of this depth at once: the weight below the cut reaches the lower
    // part's share, ⌊n/2⌋ / n of the node's.
    std::vector<double> lo(cut.size()), hi(cut.size()), below(cut.size());
    for (std::size_t c = 0; c < cut.size(); ++c) {
      const Box& box = boxes[cut[c]];
      const int axis = nodes[cut[c]].axis;
      lo[c] = box.min()[axis];
      hi[c] = box.max()[axis];
    }
    for (int halving = 0; halving < 60 && !cut.empty(); ++halving) {
      for (std::size_t c = 0; c < cut.size(); ++c) {
        const double mid = 0.5 * (lo[c] + hi[c]);
        const auto n =
            std::lower_bound(sorted[c].begin(), sorted[c].end(), mid) - sorted[c].begin();
        below[c] = prefix[c][static_cast<std::size_t>(n)];
      }
      comm.sum(below);
      for (std::size_t c = 0; c < cut.size(); ++c) {
        const Node& node = nodes[cut[c]];
        const double target = total[c] * (node.count / 2) / node.count;
        const double mid = 0.5 * (lo[c] + hi[c]);
        (below[c] < target ? lo[c] : hi[c]) = mid;
      }
    }
    for (std::size_t c = 0; c < cut.size(); ++c) {
      Node& node = nodes[cut[c]];
      const Box& box = boxes[cut[c]];
      const double a = box.min()[node.axis], b = box.max()[node.axis];
      node.cut = total[c] > 0.0 ? inside(hi[c], a, b)
                                : inside(a + (b - a) * (node.count / 2) / node.count, a, b);
    }
    // The children's boxes, and each body one level down.
    for (std::size_t k = first; k < last; ++k) {
      const Node& node = nodes[k];
      if (node.count == 1) continue;
      Box lower = boxes[k], upper = boxes[k];
      lower.max()[node.axis] = node.cut;
      upper.min()[node.axis] = node.cut;
      boxes.resize(std::max<std::size_t>(boxes.size(), static_cast<std::size_t>(node.upper) + 1));
      boxes[static_cast<std::size_t>(node.lower)] = lower;
      boxes[static_cast<std::size_t>(node.upper)] = upper;
    }
    for (std::size_t i = 0; i < at.size(); ++i) {
      const Node& node = nodes[static_cast<std::size_t>(node_of[i])];
      if (node.count == 1) continue;
      node_of[i] = at[i][node.axis] < node.cut ? node.lower : node.upper;
    }
    // In breadth-first order the next depth follows this one: up to the last child.
    std::size_t next = last;
    for (std::size_t k = first; k < last; ++k) {
      if (nodes[k].count > 1) next = std::max(next, static_cast<std::size_t>(nodes[k].upper) + 1);
    }
    first = last;
    last = next;
  }
  tree.make_leaves();
  return tree;
}
// [bisection tree]

void BisectionTree::make_leaves() {
  leaves_.assign(static_cast<std::size_t>(nodes_.front().count), domain());
  std::vector<Box> boxes(nodes_.size(), domain());
  for (std::size_t k = 0; k < nodes_.size(); ++k) {
    const Node& node = nodes_[k];
    if (node.count == 1) {
      leaves_[static_cast<std::size_t>(node.first)] = boxes[k];
      continue;
    }
    Box lower = boxes[k], upper = boxes[k];
    lower.max()[node.axis] = node.cut;
    upper.min()[node.axis] = node.cut;
    boxes[static_cast<std::size_t>(node.lower)] = lower;
    boxes[static_cast<std::size_t>(node.upper)] = upper;
  }
}

Box BisectionTree::subdomain(int rank) const {
  if (rank < 0 || rank >= size()) {
    throw InvalidArgument("BisectionTree: expected a rank in [0, " + std::to_string(size()) +
                          "), found " + std::to_string(rank));
  }
  return leaves_[static_cast<std::size_t>(rank)];
}

// [tree owner]
int BisectionTree::owner_of(const Vector3& position) const {
  const Vector3 p = wrap(position);
  std::size_t k = 0;
  while (nodes_[k].count > 1) {
    const Node& node = nodes_[k];
    k = static_cast<std::size_t>(p[node.axis] < node.cut ? node.lower : node.upper);
  }
  return nodes_[k].first;
}
// [tree owner]

std::vector<double> BisectionTree::cuts() const {
  std::vector<double> all;
  for (const Node& node : nodes_) {
    all.push_back(node.axis);
    all.push_back(node.cut);
  }
  return all;
}

std::unique_ptr<Partition> BisectionTree::with_cuts(std::span<const double> cuts) const {
  // The shape of the tree is the even tree's for as many processes; the cuts are the given ones.
  auto tree = std::make_unique<BisectionTree>(domain(), size(), periodic());
  if (cuts.size() != 2 * tree->nodes_.size()) {
    throw InvalidArgument("BisectionTree: expected an axis and a cut for each of the " +
                          std::to_string(tree->nodes_.size()) + " nodes of a tree of " +
                          std::to_string(size()) + " leaves, found " +
                          std::to_string(cuts.size()) + " numbers");
  }
  for (std::size_t k = 0; k < tree->nodes_.size(); ++k) {
    Node& node = tree->nodes_[k];
    const double axis = cuts[2 * k], cut = cuts[2 * k + 1];
    const bool leaf = node.count == 1;
    if (leaf ? axis != -1.0 : !(axis == 0.0 || axis == 1.0 || axis == 2.0) || !std::isfinite(cut)) {
      throw InvalidArgument("BisectionTree: node " + std::to_string(k) + " expected " +
                            (leaf ? std::string("a leaf (axis -1)")
                                  : std::string("an axis 0, 1 or 2 and a finite cut")) +
                            ", found axis " + format_number(axis) + " and cut " +
                            format_number(cut));
    }
    node.axis = static_cast<int>(axis);
    node.cut = cut;
  }
  tree->make_leaves();
  return tree;
}

std::unique_ptr<Partition> BisectionTree::rebalanced(const Communicator& comm,
                                                     std::span<const Vector3> centres,
                                                     std::span<const double> weights) const {
  return std::make_unique<BisectionTree>(
      balanced(comm, domain(), size(), periodic(), centres, weights));
}

}  // namespace grbd::parallel
