#pragma once
/// \file
/// \brief The domain split among processes (chapter 8): a Cartesian grid of subdomains, the owner
/// of a position, and whether a body reaches into a subdomain.

#include <algorithm>
#include <array>
#include <memory>
#include <vector>

#include "grbd/core/types.hpp"
#include "grbd/parallel/partition.hpp"
#include "grbd/timestep/body_system.hpp"
#include "grbd/timestep/contacts.hpp"
#include "grbd/timestep/stepper.hpp"

namespace grbd::parallel {

/// The number of subdomains along x, y and z for `processes` processes over a domain of the given
/// extents: of all factorisations n_x n_y n_z = P, the one whose interfaces between subdomains
/// have the least area, Σ_d (n_d − 1) A_d with A_d the domain's cross-section normal to axis d
/// (ties: more cuts along x, then y). A long chute is cut along its length, a cube into cubes.
/// MPI_Dims_create ignores the domain's shape. Throws InvalidArgument for P < 1 or an extent that
/// is not positive and finite.
std::array<int, 3> grid_dims(int processes, const Vector3& extent);

/// A Cartesian grid of n_x × n_y × n_z subdomains over a domain box: subdomain (i, j, k) is
/// [b^x_i, b^x_{i+1}) × [b^y_j, b^y_{j+1}) × [b^z_k, b^z_{k+1}) with b^d_i = min_d + i L_d / n_d,
/// and belongs to rank i + n_x (j + n_y k). A position outside the domain belongs to the nearest
/// subdomain along each non-periodic axis; along a periodic axis it is wrapped into the domain
/// first. Every process builds the same grid from the same numbers and so agrees on every owner.
class CartesianGrid final : public Partition {
 public:
  /// Throws InvalidArgument for an empty or non-finite domain, or dims < 1.
  CartesianGrid(const Box& domain, const std::array<int, 3>& dims,
                const std::array<bool, 3>& periodic = {false, false, false});

  /// A grid with given boundaries (a balanced grid: balanced_grid()): `boundaries[d]` holds
  /// b^d_0 … b^d_{n_d}, strictly increasing, the first and last the domain's. Throws
  /// InvalidArgument for an empty or non-finite domain or boundaries that are not such.
  CartesianGrid(const Box& domain, const std::array<std::vector<double>, 3>& boundaries,
                const std::array<bool, 3>& periodic = {false, false, false});

  /// A copy.
  std::unique_ptr<Partition> clone() const override {
    return std::make_unique<CartesianGrid>(*this);
  }
  /// The balanced_grid() of the bodies with the same dims.
  std::vector<double> cuts() const override;
  std::unique_ptr<Partition> with_cuts(std::span<const double> cuts) const override;
  std::unique_ptr<Partition> rebalanced(const Communicator& comm, std::span<const Vector3> centres,
                                        std::span<const double> weights) const override;

  /// Number of subdomains (= processes).
  int size() const override { return dims_[0] * dims_[1] * dims_[2]; }
  /// Subdomains along x, y, z.
  const std::array<int, 3>& dims() const { return dims_; }
  /// The boundaries b^d_0 … b^d_{n_d} along axis d (the first and last are the domain's).
  const std::vector<double>& boundaries(int axis) const { return boundaries_[axis]; }

  /// The cell (i, j, k) of a rank, and the rank of a cell.
  std::array<int, 3> cell_of(int rank) const;
  int rank_of(const std::array<int, 3>& cell) const;  ///< i + n_x (j + n_y k)
  /// The box of a rank's subdomain.
  Box subdomain(int rank) const override;

  // [owner of]
  /// The rank that owns a position: along each axis the cell whose [b_i, b_{i+1}) holds the
  /// wrapped position (a position on a boundary belongs to the cell above it; outside the domain,
  /// to the first or last cell). Exercise 8.1.
  int owner_of(const Vector3& position) const override;
  // [owner of]

 private:
  std::array<int, 3> dims_;
  std::array<std::vector<double>, 3> boundaries_;
};

// [overlaps]
/// True when a sphere of radius `reach` about `centre` meets the box (its closed set): the
/// distance from the centre to the box is at most reach. A body of bounding radius r whose
/// contacts reach a margin m further must be known to every subdomain it overlaps with reach
/// r + m. Exercise 8.2.
bool overlaps(const Vector3& centre, double reach, const Box& box);
// [overlaps]

/// The side whose owner solves a contact, by its key: side a, or side b when side a is a static
/// object (kStaticTag). The rule of solves_contact(), for where only the key is at hand: the warm
/// starts that travel with a migrating body, and those a restart sends to their solver.
inline timestep::GlobalId solving_side(const timestep::ContactKey& key) {
  return (key.a & timestep::kStaticTag) != 0 ? key.b : key.a;
}

/// The margin of the ghosts [m]: a contact is detected within the largest of contact_tolerance,
/// look_ahead and look_ahead_reach, times tolerance_radius, of a gap, and the candidate pairs stay
/// valid while no body has moved more than half the skin: every body a process's bodies can touch
/// before the next rebuild lies within its bounding radius, the largest one and this margin
/// (BodyExchange, ParallelStepper).
inline double ghost_margin(const timestep::StepSettings& settings) {
  return std::max({settings.contact_tolerance, settings.look_ahead, settings.look_ahead_reach}) *
             settings.tolerance_radius +
         settings.skin;
}

/// The reach of a contact between two bodies of bounding radius at most `max_radius` [m]: two
/// such radii and the ghosts' margin — how far apart two subdomains may be and still exchange
/// ghosts, and how long a periodic axis must at least be.
inline double contact_reach(double max_radius, double margin) { return 2.0 * max_radius + margin; }

// [solves contact]
/// True when this process solves the contact: it owns the contact's side a (side b when side a is
/// a static object). Side a is the first side in the canonical order of keys, decided by kinds and
/// global ids, so every process that finds the contact decides alike, and exactly one of them —
/// the owner of that side — keeps it. Exercise 8.3.
bool solves_contact(const timestep::BodySystem& system, const timestep::DetectedContact& contact);
// [solves contact]

}  // namespace grbd::parallel
