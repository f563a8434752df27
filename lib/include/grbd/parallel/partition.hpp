#pragma once
/// \file
/// \brief A partition of the domain among processes (chapter 8): what every decomposition tells
/// the engine — the subdomain of each process, the owner of a position, the neighbours within a
/// reach, the periodic images — whether it is a Cartesian grid or a bisection tree.

#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <span>
#include <vector>

#include "grbd/core/communicator.hpp"
#include "grbd/core/types.hpp"

namespace grbd::parallel {

/// An axis-aligned box [min, max] in frame I [m].
using Box = Eigen::AlignedBox3d;

/// A domain cut into size() subdomains, one per process: the subdomains tile the domain, and every
/// position has exactly one owner (a position outside the domain belongs to the nearest subdomain
/// along each non-periodic axis; along a periodic axis it is wrapped into the domain first). Every
/// process builds the same partition from the same numbers and so agrees on every owner. The
/// engine (BodyExchange, ParallelStepper) sees only this interface; CartesianGrid and
/// BisectionTree implement it.
class Partition {
 public:
  // [partition]
  virtual ~Partition() = default;
  /// A copy of the same kind.
  virtual std::unique_ptr<Partition> clone() const = 0;
  /// The partition of the same kind and size over the same domain whose cuts share the weight of
  /// the bodies' centres evenly (collective: each process passes its own bodies and every process
  /// gets the same partition). Throws InvalidArgument for spans of different lengths or a negative
  /// or non-finite weight.
  virtual std::unique_ptr<Partition> rebalanced(const Communicator& comm,
                                                std::span<const Vector3> centres,
                                                std::span<const double> weights) const = 0;

  /// The cuts as numbers (CartesianGrid: its boundaries along x, y and z; BisectionTree: each
  /// node's axis and cut): what a checkpoint keeps, so that a restart on as many processes goes on
  /// over the same subdomains after a balance moved them.
  virtual std::vector<double> cuts() const = 0;
  /// The partition of the same kind, size and domain over `cuts` (as cuts() gives them); throws
  /// InvalidArgument when they do not fit it.
  virtual std::unique_ptr<Partition> with_cuts(std::span<const double> cuts) const = 0;

  /// Number of subdomains (= processes).
  virtual int size() const = 0;
  /// The box of a rank's subdomain; throws InvalidArgument for a rank outside [0, size()).
  virtual Box subdomain(int rank) const = 0;
  /// The rank that owns a position.
  virtual int owner_of(const Vector3& position) const = 0;
  // [partition]

  /// The whole domain.
  const Box& domain() const { return domain_; }
  /// Whether each axis is periodic.
  const std::array<bool, 3>& periodic() const { return periodic_; }
  /// The region whose bodies a rank owns: its subdomain, extended to ±∞ along each non-periodic
  /// axis where it ends the domain (a body outside the domain belongs to the nearest subdomain,
  /// and its ghosts must go where its contacts are, also beyond the domain).
  Box owned_region(int rank) const;
  /// The shifts s ∈ {−1, 0, 1}³, in periods, that the periodic axes allow — the images of a
  /// position or a subdomain — (0, 0, 0) first.
  const std::vector<std::array<int, 3>>& image_shifts() const { return shifts_; }
  /// The displacement of a shift in periods: s_d L_d along each axis [m].
  Vector3 shift(const std::array<int, 3>& s) const;
  /// A position moved into the domain along the periodic axes (unchanged along the others).
  Vector3 wrap(const Vector3& position) const;
  /// The ranks whose subdomain, or a periodic image of it, lies within `reach` of the subdomain of
  /// `rank` (distance between the boxes ≤ reach), sorted, each once; `rank` itself only through a
  /// periodic image. The processes that must exchange ghosts with `rank` when bodies interact up to
  /// `reach`. O(P) per call. Throws InvalidArgument for a reach that is negative or not finite.
  std::vector<int> neighbours(int rank, double reach) const;

 protected:
  /// Throws InvalidArgument, naming `kind`, for an empty or non-finite domain.
  Partition(const Box& domain, const std::array<bool, 3>& periodic, const char* kind);
  /// Copied by the implementations' clone().
  Partition(const Partition&) = default;
  /// Assigned as a whole by an implementation of the same kind.
  Partition& operator=(const Partition&) = default;

 private:
  Box domain_;
  std::array<bool, 3> periodic_;
  std::vector<std::array<int, 3>> shifts_;
};

}  // namespace grbd::parallel
