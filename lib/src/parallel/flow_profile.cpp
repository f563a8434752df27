/// \file
/// \brief Depth profiles of a steady flow on an incline, and the μ(I) law.

#include "grbd/parallel/flow_profile.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/timestep/body_record.hpp"

namespace grbd::parallel {

namespace {

// The volume of a sphere of radius r centred at height c between the heights a < b.
double slice_volume(double c, double r, double a, double b) {
  const double lo = std::clamp(a - c, -r, r), hi = std::clamp(b - c, -r, r);
  const auto F = [r](double s) { return M_PI * (r * r * s - s * s * s / 3.0); };
  return F(hi) - F(lo);
}

}  // namespace

DepthProfile::DepthProfile(double z0, double bin, std::size_t bins, double area, double density)
    : z0_(z0), bin_(bin), area_(area), density_(density) {
  if (!std::isfinite(z0))
    throw InvalidArgument("DepthProfile: expected a finite z0, found " + format_number(z0));
  require_positive_finite("DepthProfile", "bin", bin);
  require_positive_finite("DepthProfile", "area", area);
  require_positive_finite("DepthProfile", "density", density);
  if (bins < 1) throw InvalidArgument("DepthProfile: expected at least one bin, found 0");
  volume_.assign(bins, 0.0);
  momentum_.assign(bins, 0.0);
  sxz_.assign(bins, 0.0);
  szz_.assign(bins, 0.0);
}

void DepthProfile::add_bodies(std::span<const Vector3> centres, std::span<const Vector3> velocities,
                              std::span<const double> radii) {
  if (centres.size() != velocities.size() || centres.size() != radii.size()) {
    throw InvalidArgument(
        "DepthProfile::add_bodies: expected as many velocities and radii as "
        "centres (" +
        std::to_string(centres.size()) + "), found " + std::to_string(velocities.size()) + " and " +
        std::to_string(radii.size()));
  }
  const auto n = static_cast<std::ptrdiff_t>(volume_.size());
  for (std::size_t i = 0; i < centres.size(); ++i) {
    const double c = centres[i].z(), r = radii[i];
    const auto first =
        std::max<std::ptrdiff_t>(0, static_cast<std::ptrdiff_t>(std::floor((c - r - z0_) / bin_)));
    const auto last = std::min<std::ptrdiff_t>(
        n - 1, static_cast<std::ptrdiff_t>(std::floor((c + r - z0_) / bin_)));
    for (std::ptrdiff_t k = first; k <= last; ++k) {
      const double a = z0_ + static_cast<double>(k) * bin_;
      const double v = slice_volume(c, r, a, a + bin_);
      volume_[static_cast<std::size_t>(k)] += v;
      momentum_[static_cast<std::size_t>(k)] += v * velocities[i].x();
    }
  }
  ++body_samples_;
}

void DepthProfile::add_contacts(std::span<const io::RecordContact> contacts, double dt) {
  require_positive_finite("DepthProfile::add_contacts", "dt", dt);
  const auto n = static_cast<std::ptrdiff_t>(volume_.size());
  const double slab = area_ * bin_;
  for (const io::RecordContact& c : contacts) {
    if (c.key.a >= timestep::kStaticTag || c.key.b >= timestep::kStaticTag) continue;
    const Vector3 a(c.line[0], c.line[1], c.line[2]), b(c.line[3], c.line[4], c.line[5]);
    const Vector3 l = a - b;  // from b's centre to a's
    const Vector3 n_ba(c.normal[0], c.normal[1], c.normal[2]);
    const Vector3 f =
        (c.lambda_N * n_ba + Vector3(c.lambda_T[0], c.lambda_T[1], c.lambda_T[2])) / dt;
    // σ = −(1/V) Σ f ⊗ (centre of b − centre of a): compression positive.
    const double xz = f.x() * l.z(), zz = f.z() * l.z();
    const double lo = std::min(a.z(), b.z()), hi = std::max(a.z(), b.z());
    if (hi - lo < 1e-12 * bin_) {
      const auto k = static_cast<std::ptrdiff_t>(std::floor((c.point[2] - z0_) / bin_));
      if (k >= 0 && k < n) {
        sxz_[static_cast<std::size_t>(k)] += xz / slab;
        szz_[static_cast<std::size_t>(k)] += zz / slab;
      }
      continue;
    }
    const auto first =
        std::max<std::ptrdiff_t>(0, static_cast<std::ptrdiff_t>(std::floor((lo - z0_) / bin_)));
    const auto last =
        std::min<std::ptrdiff_t>(n - 1, static_cast<std::ptrdiff_t>(std::floor((hi - z0_) / bin_)));
    for (std::ptrdiff_t k = first; k <= last; ++k) {
      const double a_k = z0_ + static_cast<double>(k) * bin_;
      const double share = (std::min(hi, a_k + bin_) - std::max(lo, a_k)) / (hi - lo);
      sxz_[static_cast<std::size_t>(k)] += share * xz / slab;
      szz_[static_cast<std::size_t>(k)] += share * zz / slab;
    }
  }
  ++contact_samples_;
}

std::vector<double> DepthProfile::z() const {
  std::vector<double> z(volume_.size());
  for (std::size_t k = 0; k < z.size(); ++k) z[k] = z0_ + (static_cast<double>(k) + 0.5) * bin_;
  return z;
}

std::vector<double> DepthProfile::packing() const {
  std::vector<double> phi(volume_.size(), 0.0);
  if (body_samples_ == 0) return phi;
  for (std::size_t k = 0; k < phi.size(); ++k) {
    phi[k] = volume_[k] / (area_ * bin_ * static_cast<double>(body_samples_));
  }
  return phi;
}

std::vector<double> DepthProfile::velocity() const {
  std::vector<double> u(volume_.size(), 0.0);
  for (std::size_t k = 0; k < u.size(); ++k) {
    if (volume_[k] > 0.0) u[k] = momentum_[k] / volume_[k];
  }
  return u;
}

std::vector<double> DepthProfile::shear_stress() const {
  std::vector<double> s(sxz_.size(), 0.0);
  if (contact_samples_ == 0) return s;
  for (std::size_t k = 0; k < s.size(); ++k) s[k] = sxz_[k] / static_cast<double>(contact_samples_);
  return s;
}

std::vector<double> DepthProfile::normal_stress() const {
  std::vector<double> s(szz_.size(), 0.0);
  if (contact_samples_ == 0) return s;
  for (std::size_t k = 0; k < s.size(); ++k) s[k] = szz_[k] / static_cast<double>(contact_samples_);
  return s;
}

std::vector<double> DepthProfile::weight_stress(double g_normal) const {
  const std::vector<double> phi = packing();
  std::vector<double> p(phi.size(), 0.0);
  double above = 0.0;
  for (std::size_t k = phi.size(); k-- > 0;) {
    p[k] = density_ * g_normal * (above + 0.5 * phi[k] * bin_);
    above += phi[k] * bin_;
  }
  return p;
}

double mu_of_i(double inertial, double mu_s, double mu_2, double i0) {
  return mu_s + (mu_2 - mu_s) / (i0 / inertial + 1.0);
}

}  // namespace grbd::parallel
