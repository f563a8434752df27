/// \file
/// \brief A Cartesian grid balanced by weighted quantiles along each axis.

#include "grbd/parallel/balance.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "grbd/core/error.hpp"

namespace grbd::parallel {

void require_weights(std::span<const Vector3> centres, std::span<const double> weights,
                     const char* where) {
  if (centres.size() != weights.size()) {
    throw InvalidArgument(std::string(where) + ": expected one weight per centre, found " +
                          std::to_string(weights.size()) + " for " +
                          std::to_string(centres.size()));
  }
  for (const double w : weights) {
    if (!(w >= 0.0) || !std::isfinite(w)) {
      throw InvalidArgument(std::string(where) + ": expected weights >= 0, found " +
                            std::to_string(w));
    }
  }
}

std::vector<double> CartesianGrid::cuts() const {
  std::vector<double> all;
  for (int d = 0; d < 3; ++d) all.insert(all.end(), boundaries(d).begin(), boundaries(d).end());
  return all;
}

std::unique_ptr<Partition> CartesianGrid::with_cuts(std::span<const double> cuts) const {
  std::array<std::vector<double>, 3> b;
  std::size_t at = 0;
  for (int d = 0; d < 3; ++d) {
    const auto n = static_cast<std::size_t>(dims()[static_cast<std::size_t>(d)]) + 1;
    if (at + n > cuts.size()) break;
    b[static_cast<std::size_t>(d)].assign(cuts.begin() + static_cast<std::ptrdiff_t>(at),
                                          cuts.begin() + static_cast<std::ptrdiff_t>(at + n));
    at += n;
  }
  if (at != cuts.size() || b[2].empty()) {
    throw InvalidArgument("CartesianGrid: expected " +
                          std::to_string(dims()[0] + dims()[1] + dims()[2] + 3) +
                          " boundaries for a grid of " + std::to_string(size()) +
                          " subdomains, found " + std::to_string(cuts.size()));
  }
  return std::make_unique<CartesianGrid>(domain(), b, periodic());
}

std::unique_ptr<Partition> CartesianGrid::rebalanced(const Communicator& comm,
                                                     std::span<const Vector3> centres,
                                                     std::span<const double> weights) const {
  return std::make_unique<CartesianGrid>(
      balanced_grid(comm, domain(), dims(), periodic(), centres, weights));
}

// [balanced grid]
CartesianGrid balanced_grid(const Communicator& comm, const Box& domain,
                            const std::array<int, 3>& dims, const std::array<bool, 3>& periodic,
                            std::span<const Vector3> centres, std::span<const double> weights) {
  require_weights(centres, weights, "balanced_grid");
  const CartesianGrid even(domain, dims, periodic);  // checks domain and dims
  // The bisection of every cut of every axis at once: [lo, hi] brackets each cut.
  struct Cut {
    int axis;
    double target;  // the weight below the cut
    double lo, hi;
  };
  std::vector<double> total{0.0};
  for (const double w : weights) total[0] += w;
  comm.sum(total);
  std::array<std::vector<double>, 3> boundaries;
  std::vector<Cut> cuts;
  for (int d = 0; d < 3; ++d) boundaries[d] = even.boundaries(d);
  if (!(total[0] > 0.0)) return even;
  for (int d = 0; d < 3; ++d) {
    for (int k = 1; k < dims[d]; ++k) {
      cuts.push_back({d, total[0] * k / dims[d], domain.min()[d], domain.max()[d]});
    }
  }
  // Along each axis, this process's coordinates as the grid sees them (wrapped, clamped into the
  // domain), sorted, with the prefix sums of their weights: the weight below a cut is then one
  // binary search, O(log n) per cut and halving.
  std::array<std::vector<double>, 3> sorted, prefix;
  for (int d = 0; d < 3; ++d) {
    if (dims[d] == 1) continue;
    std::vector<std::pair<double, double>> along(centres.size());
    for (std::size_t i = 0; i < centres.size(); ++i) {
      const double v = even.wrap(centres[i])[d];
      along[i] = {std::clamp(v, domain.min()[d], domain.max()[d]), weights[i]};
    }
    std::sort(along.begin(), along.end());
    sorted[d].resize(along.size());
    prefix[d].assign(along.size() + 1, 0.0);
    for (std::size_t i = 0; i < along.size(); ++i) {
      sorted[d][i] = along[i].first;
      prefix[d][i + 1] = prefix[d][i] + along[i].second;
    }
  }
  std::vector<double> below(cuts.size());
  for (int halving = 0; halving < 60; ++halving) {
    for (std::size_t c = 0; c < cuts.size(); ++c) {
      const auto d = static_cast<std::size_t>(cuts[c].axis);
      const double mid = 0.5 * (cuts[c].lo + cuts[c].hi);
      const auto n = std::lower_bound(sorted[d].begin(), sorted[d].end(), mid) - sorted[d].begin();
      below[c] = prefix[d][static_cast<std::size_t>(n)];
    }
    comm.sum(below);
    for (std::size_t c = 0; c < cuts.size(); ++c) {
      const double mid = 0.5 * (cuts[c].lo + cuts[c].hi);
      (below[c] < cuts[c].target ? cuts[c].lo : cuts[c].hi) = mid;
    }
  }
  std::size_t c = 0;
  for (int d = 0; d < 3; ++d) {
    std::vector<double>& b = boundaries[d];
    const double gap = 1e-9 * (domain.max()[d] - domain.min()[d]);
    for (int k = 1; k < dims[d]; ++k, ++c) {
      b[static_cast<std::size_t>(k)] =
          std::max(cuts[c].hi, b[static_cast<std::size_t>(k) - 1] + gap);
    }
    // The last cuts may have been pushed against the domain's end: keep the order there too.
    for (int k = dims[d] - 1; k >= 1; --k) {
      const auto i = static_cast<std::size_t>(k);
      b[i] = std::min(b[i], b[i + 1] - gap);
    }
  }
  return CartesianGrid(domain, boundaries, periodic);
}
// [balanced grid]

}  // namespace grbd::parallel
