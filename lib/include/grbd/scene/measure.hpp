#pragma once
/// \file
/// \brief Measurements of granular experiments (chapter 7): Love's mean stress in horizontal
/// slices from the contact percussions, the Janssen length, a steady rate from a cumulative
/// series (a silo's mass flow), Beverloo's law fitted to flow rates, and the surface and angle of
/// a heap.

#include <cstddef>
#include <span>
#include <vector>

#include "grbd/core/types.hpp"
#include "grbd/scene/simulation.hpp"

namespace grbd::scene {

/// Horizontal slices [z0 + k h, z0 + (k + 1) h), k = 0 … count − 1, of a vertical column of
/// cross-section `area` (a silo): slice k has the volume V = area h.
struct Slices {
  double z0 = 0.0;        ///< bottom of slice 0 [m]
  double h = 0.0;         ///< thickness [m] > 0
  std::size_t count = 0;  ///< number of slices
  double area = 0.0;      ///< cross-section [m²] > 0
  /// The slice the height z falls in, or count when it lies below z0 or above the last slice.
  std::size_t slice_of(double z) const;
};

/// The width of a silo along x: the distance between the static half-spaces whose normals lie
/// along ±x (its side walls). Throws InvalidArgument, naming the scene file, unless the scene has
/// two such planes at different places.
double silo_width(const Scene& scene);

/// The force of a contact on its side a over the last step, from its percussion
/// Λ = (Λ_N, Λ_T1, Λ_T2): F = (n Λ_N + t1 Λ_T1 + t2 Λ_T2)/Δt [N].
Vector3 contact_force(const contact::CompactContact& contact, const Vector3& Lambda, double dt);

// [slice stresses declaration]
/// Love's mean stress of each slice from the contact percussions of the last step:
/// σ = (1/V) Σ over the bodies whose centres lie in the slice of Σ over their contacts of F ⊗ r,
/// F the force on the body and r the lever arm from its centre to the contact point (both sides
/// of a contact between two bodies count; a static side has no centre). Compressive stresses are
/// negative; the tensor is symmetric in equilibrium. Throws InvalidArgument for h ≤ 0 or
/// area ≤ 0.
std::vector<Matrix3> slice_stresses(const Simulation& sim, const Slices& slices);
// [slice stresses declaration]

/// The mass of the bodies whose centres lie in each slice [kg].
std::vector<double> slice_masses(const Simulation& sim, const Slices& slices);

/// Janssen's length: the λ that minimises Σ_k (σ_k − ρ_b g λ (1 − e^(−d_k/λ)))² over
/// λ ∈ [10⁻⁴, 10²] m, for the vertical stresses σ_k [Pa] at depths d_k [m] below the free
/// surface and the weight density ρ_b g [N/m³]. Throws InvalidArgument for series of different
/// lengths, fewer than 2 points, or a weight density that is not > 0.
double fit_janssen_length(std::span<const double> depth, std::span<const double> sigma_v,
                          double weight_density);

/// A steady rate with its uncertainty.
struct Rate {
  double rate = 0.0;       ///< the least-squares slope [unit of the series per second]
  double error = 0.0;      ///< the standard error of the mean of the block slopes
  std::size_t blocks = 0;  ///< number of blocks the error comes from
};

// [steady rate declaration]
/// The steady rate of a cumulative series m(t) (the mass a silo discharged by time t): the
/// least-squares slope of the points with t ≥ t_start, and as its uncertainty the standard error
/// σ/√B of the slopes of B consecutive blocks of equal duration (batch means: the increments of a
/// discharge are correlated from step to step, which the scatter about one line would hide).
/// Throws InvalidArgument for series of different lengths, times that do not increase, B < 2, or
/// fewer than 2 points per block after t_start.
Rate steady_rate(std::span<const double> t, std::span<const double> m, double t_start,
                 std::size_t blocks = 5);
// [steady rate declaration]

/// Beverloo's law fitted to flow rates.
struct BeverlooFit {
  double C = 0.0;    ///< the discharge coefficient
  double k = 0.0;    ///< the empty annulus, in particle diameters
  double rms = 0.0;  ///< root mean square of W_fit/W − 1 over the points
};

// [beverloo fit declaration]
/// Beverloo, Leniger and van de Velde (1961): W = C ρ_b √g (D − k d)^(5/2). Fitted, as they did,
/// on the straight line (W/(ρ_b √g))^(2/5) = C^(2/5) D − C^(2/5) k d by least squares in D; one
/// bulk density per point. Throws InvalidArgument for series of different lengths, fewer than 2
/// points, fewer than 2 distinct D, or a rate, density, g or d that is not > 0.
BeverlooFit fit_beverloo(std::span<const double> D, std::span<const double> W,
                         std::span<const double> rho_b, double g, double d);
// [beverloo fit declaration]

/// W = C ρ_b √g (D − k d)^(5/2), 0 when D ≤ k d [kg/s].
double beverloo_rate(double C, double k, double rho_b, double g, double D, double d);

/// The free surface of a heap along x: in bins of width w over [−L, L], the highest centre of a
/// dynamic body (0 in a bin with none); fixed bodies (a rough base) are left out.
struct HeapSurface {
  std::vector<double> x;    ///< bin centres [m]
  std::vector<double> top;  ///< the highest centre in each [m]
};

/// The surface of the heap in `system`. Throws InvalidArgument unless L > 0 and 0 < w ≤ 2L.
HeapSurface heap_surface(const timestep::BodySystem& system, double L, double w);

/// The flanks of a heap as one straight line z = a + b |x| over the bins with
/// x_min ≤ |x| ≤ x_max and a body (both flanks together, a symmetric heap).
struct FlankFit {
  double a = 0.0;            ///< height at the axis [m]
  double b = 0.0;            ///< slope (< 0 for a heap)
  double angle = 0.0;        ///< atan(−b) [degrees]
  double angle_error = 0.0;  ///< its least-squares standard error [degrees]
  double rms = 0.0;          ///< of the residuals [m]
  std::size_t bins = 0;      ///< bins in the fit
};

/// Least squares over the flank bins; the standard error of b is s/√Σ(r − r̄)² with
/// s² = Σ residual²/(n − 2). Throws InvalidArgument for fewer than 3 bins in the window.
FlankFit fit_flanks(const HeapSurface& surface, double x_min, double x_max);

/// The largest speed |I_v_S| of a dynamic body [m/s] (0 without one).
double max_speed(const timestep::BodySystem& system);

/// True when every dynamic body moves slower than `speed` [m/s]: max_speed(system) < speed.
bool at_rest(const timestep::BodySystem& system, double speed);

}  // namespace grbd::scene
