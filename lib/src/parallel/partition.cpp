/// \file
/// \brief What every partition of the domain shares: periodic images, wrapping, neighbours.

#include "grbd/parallel/partition.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::parallel {

Partition::Partition(const Box& domain, const std::array<bool, 3>& periodic, const char* kind)
    : domain_(domain), periodic_(periodic) {
  const Vector3 extent = domain.sizes();
  if (!domain.min().allFinite() || !domain.max().allFinite() || !(extent.minCoeff() > 0.0)) {
    throw InvalidArgument(std::string(kind) +
                          ": expected a finite domain of positive extent, "
                          "found " +
                          format_number(extent[0]) + " × " + format_number(extent[1]) + " × " +
                          format_number(extent[2]) + " m");
  }
  shifts_.push_back({0, 0, 0});
  for (int sz = -1; sz <= 1; ++sz) {
    for (int sy = -1; sy <= 1; ++sy) {
      for (int sx = -1; sx <= 1; ++sx) {
        const bool none = sx == 0 && sy == 0 && sz == 0;
        if (none || (sx && !periodic_[0]) || (sy && !periodic_[1]) || (sz && !periodic_[2]))
          continue;
        shifts_.push_back({sx, sy, sz});
      }
    }
  }
}

Box Partition::owned_region(int rank) const {
  Box box = subdomain(rank);
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  for (int d = 0; d < 3; ++d) {
    if (periodic_[static_cast<std::size_t>(d)]) continue;
    if (box.min()[d] == domain_.min()[d]) box.min()[d] = -kInfinity;
    if (box.max()[d] == domain_.max()[d]) box.max()[d] = kInfinity;
  }
  return box;
}

Vector3 Partition::shift(const std::array<int, 3>& s) const {
  const Vector3 L = domain_.sizes();
  return Vector3(s[0] * L.x(), s[1] * L.y(), s[2] * L.z());
}

Vector3 Partition::wrap(const Vector3& position) const {
  Vector3 x = position;
  for (int d = 0; d < 3; ++d) {
    if (!periodic_[static_cast<std::size_t>(d)]) continue;
    const double lo = domain_.min()[d];
    const double length = domain_.max()[d] - lo;
    x[d] -= length * std::floor((x[d] - lo) / length);
    if (x[d] >= domain_.max()[d]) x[d] = lo;  // x a hair below lo rounds up to max
  }
  return x;
}

std::vector<int> Partition::neighbours(int rank, double reach) const {
  if (!(reach >= 0.0) || !std::isfinite(reach)) {
    throw InvalidArgument("Partition::neighbours: expected a finite reach >= 0, found " +
                          format_number(reach));
  }
  const Box mine = subdomain(rank);
  std::vector<int> found;
  for (int other = 0; other < size(); ++other) {
    const Box box = subdomain(other);
    // The subdomain and its images, shifted by −L, 0, +L along each periodic axis.
    for (const std::array<int, 3>& s : shifts_) {
      if (other == rank && s == shifts_.front()) continue;  // this subdomain itself
      const Vector3 d = shift(s);
      if (mine.exteriorDistance(Box(box.min() + d, box.max() + d)) <= reach) {
        found.push_back(other);
        break;
      }
    }
  }
  return found;  // ascending, each once
}

}  // namespace grbd::parallel
