#pragma once
/// \file
/// \brief Steady flow down a rough incline (chapter 8): profiles across the depth of a layer
/// periodic along and across the flow — packing fraction, velocity, stresses from the contact
/// percussions — and the laws they are held against: Bagnold's profile and the inertial number.

#include <cstddef>
#include <span>
#include <vector>

#include "grbd/core/types.hpp"
#include "grbd/io/output.hpp"

namespace grbd::parallel {

/// Profiles across the depth of a flowing layer in a box periodic along x and y: bins of height
/// `bin` from z = z0 up, each the slab of the box's plan area between its heights, averaged over
/// every sample added. The flow goes along +x, gravity g (sin θ, 0, −cos θ).
class DepthProfile {
 public:
  /// `bins` slabs of height `bin` [m] from `z0` [m] up, over a plan area `area` [m²]; beads of
  /// density `density` [kg/m³]. InvalidArgument unless bins ≥ 1 and bin, area, density are
  /// positive and finite and z0 finite.
  DepthProfile(double z0, double bin, std::size_t bins, double area, double density);

  /// Adds one sample: the spheres (centres, velocities, radii, spans of equal length) as a record
  /// holds them. Each sphere is cut by the slabs exactly: a slab gets the volume of the sphere
  /// between its heights, and the sphere's velocity weighted by that volume.
  void add_bodies(std::span<const Vector3> centres, std::span<const Vector3> velocities,
                  std::span<const double> radii);

  /// Adds one sample of contacts, the percussions of a step of length dt [s]: the stress of the
  /// contact forces f = λ/Δt over the branch vectors ℓ from side b's centre to side a's (Love and
  /// Weber), σ = (1/V) Σ f ⊗ ℓ with f the force on side a, positive in compression, each contact
  /// shared among the slabs its branch vector crosses in proportion to the height it spends in
  /// each (all to the slab of its point where the branch is level). Contacts with a static object
  /// (timestep::kStaticTag ids) carry no branch and are left out; a fixed body has no centre in a
  /// record (io::RecordContact::line starts at the contact point), so a contact with one counts
  /// from its contact point up, and a profile of a layer on a fixed base is whole above the
  /// base's contact points.
  void add_contacts(std::span<const io::RecordContact> contacts, double dt);

  /// Heights of the slabs' centres [m].
  std::vector<double> z() const;
  /// Solid fraction φ of each slab: bead volume over slab volume, mean over the samples.
  std::vector<double> packing() const;
  /// Mean velocity along x of the bead material in each slab [m/s] (0 where there was none).
  std::vector<double> velocity() const;
  /// Shear stress σ_xz of each slab [Pa], mean over the contact samples. Compression being
  /// positive, the layer above a slab pulls it downstream with −σ_xz: for a flow along +x, σ_xz
  /// is negative and the stress ratio μ = −σ_xz/σ_zz.
  std::vector<double> shear_stress() const;
  /// Normal stress σ_zz of each slab [Pa], mean over the contact samples.
  std::vector<double> normal_stress() const;
  /// σ_zz of each slab from the weight of the material above it, ρ g cos θ Σ φ Δz over the slabs
  /// above plus half its own [Pa], for gravity's component normal to the base `g_normal` [m/s²].
  std::vector<double> weight_stress(double g_normal) const;
  /// Samples of bodies and of contacts added.
  std::size_t body_samples() const { return body_samples_; }
  /// \copydoc body_samples
  std::size_t contact_samples() const { return contact_samples_; }

 private:
  double z0_, bin_, area_, density_;
  std::vector<double> volume_, momentum_, sxz_, szz_;
  std::size_t body_samples_ = 0, contact_samples_ = 0;
};

// [bagnold fit]
/// Bagnold's profile of a steady layer of depth h over a rough base, u(z) = A (h^{3/2} − (h −
/// z)^{3/2}) for 0 ≤ z ≤ h: the amplitude A [1/(m^{1/2} s)] that fits the measured u_i at heights
/// z_i best in least squares, Σ_i (u_i − A f_i)² least with f_i = h^{3/2} − (h − z_i)^{3/2}.
/// Exercise 8.6. InvalidArgument for spans of different lengths, a height outside [0, h], h not
/// positive and finite, or no height above the base (every f_i = 0).
double bagnold_fit(std::span<const double> z, std::span<const double> u, double h);
// [bagnold fit]

// [inertial number]
/// The inertial number I = γ̇ d / √(P/ρ_s) of a dense granular flow (GDR MiDi 2004; Jop, Forterre,
/// Pouliquen 2006): shear rate γ̇ [1/s], grain diameter d [m], pressure P [Pa], grain density ρ_s
/// [kg/m³]. Exercise 8.7. InvalidArgument unless d, P and ρ_s are positive and finite and γ̇ is
/// finite (a negative γ̇ counts by its size).
double inertial_number(double shear_rate, double diameter, double pressure, double density);
// [inertial number]

/// The μ(I) law of Jop, Forterre and Pouliquen (2006): μ(I) = μ_s + (μ_2 − μ_s)/(I_0/I + 1).
double mu_of_i(double inertial, double mu_s, double mu_2, double i0);

}  // namespace grbd::parallel
