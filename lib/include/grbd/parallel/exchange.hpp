#pragma once
/// \file
/// \brief Body communication among processes (chapter 8): migration of owned bodies to the process
/// that owns their centre, borders (ghost copies for every process a body reaches, periodic images
/// included) and the forward exchange of the owners' states to their ghosts — LAMMPS' exchange,
/// borders and forward communication, Nützi's migration and update.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "grbd/core/communicator.hpp"
#include "grbd/parallel/decomposition.hpp"
#include "grbd/timestep/body_system.hpp"
#include "grbd/timestep/contacts.hpp"

namespace grbd::parallel {

using timestep::image_code;   // a periodic shift's code (timestep/body_system.hpp)
using timestep::image_shift;  // the shift of a code

/// The exchanges of bodies between the processes of a Partition. Every process of the
/// communicator calls each operation at the same point (they are collective).
///
/// A body of bounding radius r needs a ghost on every process whose subdomain (or a periodic image
/// of it) it reaches within r + r_max + `margin`: every body it can touch, whose centre may lie
/// anywhere in that subdomain, then finds it there, up to the margin and for as long as the
/// ghosts are not rebuilt. The driver rebuilds (migrate(), then borders()) when some body has moved
/// more than half the skin, and calls forward() at every other step.
class BodyExchange {
 public:
  /// `margin`: contact margin plus skin [m], ≥ 0 and finite; `max_radius`: the largest bounding
  /// radius r_max a body of the run can have [m] (from the scene), > 0: the neighbours are the
  /// subdomains within 2 r_max + margin. Throws InvalidArgument for a grid whose size is not the
  /// communicator's.
  BodyExchange(const Communicator& comm, const Partition& partition, double margin,
               double max_radius);

  /// Migration: clears the ghosts, wraps the owned bodies' centres along the periodic axes, and
  /// sends every owned body whose owner is another process to it (removed here, added there, with
  /// its state). Throws grbd::Error naming the body when its new owner is not a neighbour (it
  /// crossed a whole subdomain since the last migration: the time step or the skin is too large).
  /// Returns the number of bodies this process sent.
  std::size_t migrate(timestep::BodySystem& system);
  /// Migration with warm starts: as above, and the warm starts of the contacts a leaving body
  /// decides (its side a, or its side b against a static side a: the contacts its owner solves)
  /// go with it into the new owner's table, so that its contacts stay warm-started.
  std::size_t migrate(timestep::BodySystem& system, timestep::WarmStartTable& warm);

  /// Borders: clears the ghosts and gives every process a ghost of each owned body that reaches
  /// its subdomain (within its bounding radius + r_max + margin), through periodic images too (a
  /// process can hold images of its own bodies); remembers what went where for forward().
  /// Returns the number of ghosts this process received.
  std::size_t borders(timestep::BodySystem& system);

  /// Per-body values from the owners to their ghosts: `values` holds `width` doubles per row of
  /// the system; the rows of the ghosts are overwritten with their owners' values. The layout must
  /// be the one borders() left, as for forward().
  /// With `selected` (one flag per row of the system), only the rows whose flag is set take part,
  /// on both sides: the flags of a ghost and of its owner's row must agree (forward them first).
  void forward_values(const timestep::BodySystem& system, std::span<double> values, int width,
                      std::span<const std::uint8_t> selected = {});
  /// Per-body values from the ghosts back to their owners, added: each owned row's values get the
  /// values of its ghosts on every process, in the order of the neighbours and of the last
  /// borders() (a reverse communication). Ghost rows are left as they are.
  /// With `selected`, as for forward_values().
  void reverse_add(const timestep::BodySystem& system, std::span<double> values, int width,
                   std::span<const std::uint8_t> selected = {});

  /// Forward: the owners' current states to their ghosts (positions shifted by each ghost's
  /// image), bit for bit. The system's layout must be the one borders() left (throws
  /// InvalidArgument otherwise: bodies were added, removed or reordered since).
  void forward(timestep::BodySystem& system);

  /// The processes this one exchanges with (Partition::neighbours within 2 max_radius + margin).
  const std::vector<int>& neighbours() const { return neighbours_; }

 private:
  struct Sent {
    std::vector<std::size_t> rows;  // owned rows, in message order
  };
  const Communicator& comm_;
  const Partition& partition_;
  double margin_;
  double max_radius_;
  std::vector<int> neighbours_;
  std::vector<Sent> sent_;                              // per neighbour, from the last borders()
  std::vector<std::size_t> ghost_start_, ghost_count_;  // per neighbour: rows received
  std::uint64_t layout_ = ~std::uint64_t{0};            // the system's layout after borders()
  std::vector<std::vector<std::byte>> out_, in_;        // message buffers, kept
  std::vector<std::pair<timestep::GlobalId, std::size_t>> leaving_;  // id, neighbour (migrate)
};

}  // namespace grbd::parallel
