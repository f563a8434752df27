#pragma once
/// \file
/// \brief Load balance (chapter 8): a Cartesian grid whose boundaries cut the weighted bodies into
/// equal parts along each axis, computed together by the processes that hold them.

#include <array>
#include <span>

#include "grbd/core/communicator.hpp"
#include "grbd/parallel/decomposition.hpp"

namespace grbd::parallel {

/// Throws InvalidArgument, naming `where`, unless there is one weight per centre and every weight
/// is finite and ≥ 0: the check of the bodies a balance is computed from.
void require_weights(std::span<const Vector3> centres, std::span<const double> weights,
                     const char* where);

/// The grid of `dims` subdomains over `domain` whose boundaries along each axis d cut the weighted
/// distribution of the bodies' centres along d into n_d equal parts: b^d_k is where the weight of
/// the centres below it reaches k/n_d of the whole (the weighted quantiles of each axis — recursive
/// coordinate bisection restricted to a tensor grid). Collective: every process passes its own
/// bodies (centres wrapped along the periodic axes and clamped into the domain along the others,
/// weights ≥ 0), and every process gets the same grid, whatever the bodies' distribution among the
/// processes, since the cuts are found by bisection on sums over all processes (60 halvings, each
/// one reduction for all cuts at once). A cut that would not lie above the previous one is moved
/// just above it, so that no subdomain is empty of space. Without weight anywhere the grid is the
/// even one. Throws InvalidArgument for spans of different lengths or a negative or non-finite
/// weight (on the process that has it).
CartesianGrid balanced_grid(const Communicator& comm, const Box& domain,
                            const std::array<int, 3>& dims, const std::array<bool, 3>& periodic,
                            std::span<const Vector3> centres, std::span<const double> weights);

}  // namespace grbd::parallel
