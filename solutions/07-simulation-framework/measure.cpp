/// \file
/// \brief Chapter 7 exercises: the stress of a granular column from the contact percussions, the
/// steady rate of a discharge, and Beverloo's law fitted to flow rates; with the Janssen fit.

#include "grbd/scene/measure.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <variant>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::scene {

namespace {

void require_same_length(const char* where, std::size_t a, std::size_t b) {
  if (a != b) {
    throw InvalidArgument(std::string(where) + ": expected series of the same length, found " +
                          std::to_string(a) + " and " + std::to_string(b));
  }
}

// The least-squares line y = intercept + slope x through the points (x_k, y_k),
// k ∈ [first, last), with sxx = Σ(x_k − x̄)², which its standard errors need.
struct Line {
  double slope = 0.0;
  double intercept = 0.0;
  double sxx = 0.0;
};

Line fit_line(std::span<const double> x, std::span<const double> y, std::size_t first,
              std::size_t last) {
  const auto n = static_cast<double>(last - first);
  double mx = 0.0, my = 0.0;
  for (std::size_t k = first; k < last; ++k) {
    mx += x[k];
    my += y[k];
  }
  mx /= n;
  my /= n;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t k = first; k < last; ++k) {
    sxy += (x[k] - mx) * (y[k] - my);
    sxx += (x[k] - mx) * (x[k] - mx);
  }
  const double slope = sxy / sxx;
  return {slope, my - slope * mx, sxx};
}

// The least-squares slope of the points (x_k, y_k), k ∈ [first, last).
double slope(std::span<const double> x, std::span<const double> y, std::size_t first,
             std::size_t last) {
  return fit_line(x, y, first, last).slope;
}

// The bin of width h from v0 that v falls in, or count outside [v0, v0 + count h) (and for NaN).
std::size_t bin_of(double v, double v0, double h, std::size_t count) {
  const double k = std::floor((v - v0) / h);
  if (!(k >= 0.0) || k >= static_cast<double>(count)) return count;
  return static_cast<std::size_t>(k);
}

}  // namespace

std::size_t Slices::slice_of(double z) const { return bin_of(z, z0, h, count); }

double silo_width(const Scene& scene) {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& s : scene.statics) {
    const auto* plane = std::get_if<collision::HalfSpace>(&s.shape);
    if (plane != nullptr && std::abs(plane->I_n.x()) > 0.99) {
      const double x = -plane->offset / plane->I_n.x();
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
  }
  if (!(hi > lo)) {
    throw InvalidArgument(scene.file.string() +
                          ": expected two static half-spaces with normals along x (side walls)");
  }
  return hi - lo;
}

Vector3 contact_force(const contact::CompactContact& contact, const Vector3& Lambda, double dt) {
  return (contact.n * Lambda[0] + contact.t1 * Lambda[1] + contact.t2() * Lambda[2]) / dt;
}

std::vector<Matrix3> slice_stresses(const Simulation& sim, const Slices& slices) {
  if (!(slices.h > 0.0) || !(slices.area > 0.0)) {
    throw InvalidArgument("slice_stresses: expected h > 0 and area > 0, found h = " +
                          format_number(slices.h) + ", area = " + format_number(slices.area));
  }
  std::vector<Matrix3> sigma(slices.count, Matrix3::Zero());
  const auto& problem = sim.stepper().problem();
  const auto Lambda = sim.stepper().percussions();
  const double dt = sim.scene().settings.dt;
  const auto states = sim.system().states();
  const double V = slices.area * slices.h;
  // BEGIN EXERCISE 7.3: the stress from the percussions
  // Hint: each contact adds F ⊗ r_a / V to the slice of body a and (−F) ⊗ r_b / V to that of b;
  // Hint: a static side (collision::kStatic) has no centre and adds nothing.
  auto add = [&](collision::BodyIndex body, const Vector3& r, const Vector3& F) {
    if (body == collision::kStatic) return;
    const std::size_t k = slices.slice_of(states[static_cast<std::size_t>(body)].q[2]);
    if (k < slices.count) sigma[k] += F * r.transpose() / V;
  };
  for (std::size_t c = 0; c < problem.contacts.size(); ++c) {
    const auto& contact = problem.contacts[c];
    const Vector3 F = contact_force(contact, Lambda[c], dt);  // on side a
    add(contact.body_a, contact.r_a, F);
    add(contact.body_b, contact.r_b, -F);
  }
  return sigma;
  // END EXERCISE 7.3
}

std::vector<double> slice_masses(const Simulation& sim, const Slices& slices) {
  std::vector<double> mass(slices.count, 0.0);
  const auto states = sim.system().states();
  for (std::size_t i = 0; i < states.size(); ++i) {
    const std::size_t k = slices.slice_of(states[i].q[2]);
    if (k < slices.count) mass[k] += sim.system().inertia()[i].m;
  }
  return mass;
}

// [janssen fit]
double fit_janssen_length(std::span<const double> depth, std::span<const double> sigma_v,
                          double weight_density) {
  require_same_length("fit_janssen_length", depth.size(), sigma_v.size());
  if (depth.size() < 2 || !(weight_density > 0.0)) {
    throw InvalidArgument(
        "fit_janssen_length: expected at least 2 points and a weight density > 0, found " +
        std::to_string(depth.size()) + " points and " + format_number(weight_density) + " N/m³");
  }
  // The sum of squares is unimodal in λ for data that rise and saturate: golden-section search
  // on log λ.
  auto cost = [&](double log_lambda) {
    const double l = std::exp(log_lambda);
    double sum = 0.0;
    for (std::size_t k = 0; k < depth.size(); ++k) {
      const double e = sigma_v[k] - weight_density * l * (1.0 - std::exp(-depth[k] / l));
      sum += e * e;
    }
    return sum;
  };
  double a = std::log(1e-4), b = std::log(1e2);
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int i = 0; i < 200; ++i) {
    const double x1 = b - g * (b - a), x2 = a + g * (b - a);
    if (cost(x1) < cost(x2))
      b = x2;
    else
      a = x1;
  }
  return std::exp(0.5 * (a + b));
}
// [janssen fit]

Rate steady_rate(std::span<const double> t, std::span<const double> m, double t_start,
                 std::size_t blocks) {
  require_same_length("steady_rate", t.size(), m.size());
  for (std::size_t k = 1; k < t.size(); ++k) {
    if (!(t[k] > t[k - 1])) {
      throw InvalidArgument("steady_rate: expected increasing times, found t[" +
                            std::to_string(k - 1) + "] = " + format_number(t[k - 1]) + ", t[" +
                            std::to_string(k) + "] = " + format_number(t[k]));
    }
  }
  const auto first =
      static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), t_start) - t.begin());
  const std::size_t n = t.size() - first;
  if (blocks < 2 || n < 2 * blocks) {
    throw InvalidArgument(
        "steady_rate: expected at least 2 blocks of at least 2 points after t = " +
        format_number(t_start) + ", found " + std::to_string(n) + " points for " +
        std::to_string(blocks) + " blocks");
  }
  Rate out;
  out.blocks = blocks;
  // BEGIN EXERCISE 7.4: the steady mass flow rate
  // Hint: the rate is the least-squares slope over [first, end); cut [t_first, t_last] into B
  //   blocks of equal duration, take the slope of each and the standard error of their mean.
  out.rate = slope(t, m, first, t.size());
  const double t0 = t[first];
  const double span = t.back() - t0;
  std::vector<double> rates;
  std::size_t begin = first;
  for (std::size_t b = 1; b <= blocks; ++b) {
    const double t_end = t0 + span * static_cast<double>(b) / static_cast<double>(blocks);
    std::size_t end = begin;
    while (end < t.size() && (t[end] < t_end || b == blocks)) ++end;
    if (end - begin < 2) {
      throw InvalidArgument("steady_rate: block " + std::to_string(b) +
                            " holds fewer than 2 points");
    }
    rates.push_back(slope(t, m, begin, end));
    begin = end;
  }
  double mean = 0.0;
  for (double r : rates) mean += r;
  mean /= static_cast<double>(blocks);
  double var = 0.0;
  for (double r : rates) var += (r - mean) * (r - mean);
  var /= static_cast<double>(blocks - 1);
  out.error = std::sqrt(var / static_cast<double>(blocks));
  // END EXERCISE 7.4
  return out;
}

BeverlooFit fit_beverloo(std::span<const double> D, std::span<const double> W,
                         std::span<const double> rho_b, double g, double d) {
  require_same_length("fit_beverloo", D.size(), W.size());
  require_same_length("fit_beverloo", D.size(), rho_b.size());
  if (D.size() < 2 || !(g > 0.0) || !(d > 0.0)) {
    throw InvalidArgument("fit_beverloo: expected at least 2 points, g > 0 and d > 0, found " +
                          std::to_string(D.size()) + " points, g = " + format_number(g) +
                          ", d = " + format_number(d));
  }
  for (std::size_t i = 0; i < D.size(); ++i) {
    if (!(W[i] > 0.0) || !(rho_b[i] > 0.0) || !std::isfinite(D[i])) {
      throw InvalidArgument("fit_beverloo: expected W > 0, rho_b > 0 and a finite D, found W = " +
                            format_number(W[i]) + ", rho_b = " + format_number(rho_b[i]) +
                            ", D = " + format_number(D[i]) + " at point " + std::to_string(i));
    }
  }
  if (std::all_of(D.begin(), D.end(), [&](double x) { return x == D[0]; })) {
    throw InvalidArgument("fit_beverloo: expected at least 2 distinct orifice sizes, found all " +
                          format_number(D[0]));
  }
  BeverlooFit fit;
  // BEGIN EXERCISE 7.5: Beverloo's law fitted to flow rates
  // Hint: y = (W/(ρ_b √g))^(2/5) is a straight line a D + b in D; then C = a^(5/2), k = −b/(a d).
  std::vector<double> y(D.size());
  for (std::size_t i = 0; i < D.size(); ++i) y[i] = std::pow(W[i] / (rho_b[i] * std::sqrt(g)), 0.4);
  const Line line = fit_line(D, y, 0, D.size());
  const double a = line.slope, b = line.intercept;
  fit.C = std::pow(a, 2.5);
  fit.k = -b / (a * d);
  // END EXERCISE 7.5
  if (!(fit.C > 0.0) || !std::isfinite(fit.C) || !std::isfinite(fit.k)) {
    throw InvalidArgument("fit_beverloo: the flow rates do not grow with D; no C > 0 fits them");
  }
  double sq = 0.0;
  for (std::size_t i = 0; i < D.size(); ++i) {
    const double e = beverloo_rate(fit.C, fit.k, rho_b[i], g, D[i], d) / W[i] - 1.0;
    sq += e * e;
  }
  fit.rms = std::sqrt(sq / static_cast<double>(D.size()));
  return fit;
}

double beverloo_rate(double C, double k, double rho_b, double g, double D, double d) {
  const double open = D - k * d;
  return open > 0.0 ? C * rho_b * std::sqrt(g) * std::pow(open, 2.5) : 0.0;
}

// [heap surface]
HeapSurface heap_surface(const timestep::BodySystem& system, double L, double w) {
  if (!(L > 0.0) || !(w > 0.0) || !(w <= 2.0 * L)) {
    throw InvalidArgument("heap_surface: expected L > 0 and 0 < w <= 2 L, found L = " +
                          format_number(L) + ", w = " + format_number(w));
  }
  HeapSurface s;
  const auto bins = static_cast<std::size_t>(std::round(2.0 * L / w));
  s.top.assign(bins, 0.0);
  s.x.resize(bins);
  for (std::size_t k = 0; k < bins; ++k) s.x[k] = -L + (static_cast<double>(k) + 0.5) * w;
  const auto states = system.states();
  for (std::size_t i = 0; i < states.size(); ++i) {
    if (!system.dynamic(i)) continue;  // the base
    const std::size_t k = bin_of(states[i].q[0], -L, w, bins);
    if (k < bins) s.top[k] = std::max(s.top[k], states[i].q[2]);
  }
  return s;
}

FlankFit fit_flanks(const HeapSurface& surface, double x_min, double x_max) {
  std::vector<double> r, z;
  for (std::size_t k = 0; k < surface.x.size(); ++k) {
    const double distance = std::abs(surface.x[k]);
    if (distance >= x_min && distance <= x_max && surface.top[k] > 0.0) {
      r.push_back(distance);
      z.push_back(surface.top[k]);
    }
  }
  const auto n = static_cast<double>(r.size());
  if (r.size() < 3) {
    throw InvalidArgument("fit_flanks: expected at least 3 bins with bodies in " +
                          format_number(x_min) + " <= |x| <= " + format_number(x_max) +
                          ", found " + std::to_string(r.size()));
  }
  const Line line = fit_line(r, z, 0, r.size());
  FlankFit fit;
  fit.bins = r.size();
  fit.b = line.slope;
  fit.a = line.intercept;
  double squares = 0.0;
  for (std::size_t k = 0; k < r.size(); ++k) squares += std::pow(z[k] - fit.a - fit.b * r[k], 2);
  fit.rms = std::sqrt(squares / n);
  const double b_error = std::sqrt(squares / (n - 2.0) / line.sxx);
  constexpr double kDegree = 180.0 / std::numbers::pi;
  fit.angle = std::atan(-fit.b) * kDegree;
  fit.angle_error = b_error / (1.0 + fit.b * fit.b) * kDegree;  // d atan(b)/db
  return fit;
}
// [heap surface]

double max_speed(const timestep::BodySystem& system) {
  double fastest = 0.0;
  const auto states = system.states();
  for (std::size_t i = 0; i < states.size(); ++i) {
    if (system.dynamic(i)) fastest = std::max(fastest, states[i].u.head<3>().norm());
  }
  return fastest;
}

bool at_rest(const timestep::BodySystem& system, double speed) {
  return max_speed(system) < speed;
}

}  // namespace grbd::scene
