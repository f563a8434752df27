// Chapter 7: the measurements of the experiments, against closed forms. Love's stress in a column
// of spheres resting on each other (the weight above each centre over the cross-section), a
// steady rate of a series with known block slopes, Beverloo's law fitted to rates made from it,
// and the Janssen length of stresses made from Janssen's law.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "grbd/core/error.hpp"
#include "grbd/scene/measure.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd/scene/simulation.hpp"

namespace {

using grbd::InvalidArgument;
using grbd::Matrix3;
using grbd::scene::Rate;
using grbd::scene::Slices;

// n equal spheres of radius r stacked on the floor z = 0, each touching the next, at rest.
std::string stack_scene(int n, double r) {
  std::string positions;
  for (int j = 0; j < n; ++j) {
    positions += (j > 0 ? ", " : "") + std::string("[0.001, -0.002, ") +
                 std::to_string((2 * j + 1) * r) + "]";
  }
  return R"([simulation]
dt = 1e-3
end_time = 0.01
gravity = [0, 0, -9.81]

[solver]
tolerance = 1e-12
absolute_tolerance = 1e-30
max_iterations = 10000

[[material]]
name = "glass"

[default_contact]
mu = 0.5

[[static]]
shape = "half_space"
normal = [0, 0, 1]
material = "glass"

[[bodies]]
radius = )" +
         std::to_string(r) +
         R"(
density = 2500
material = "glass"
positions = [)" +
         positions + "]\n";
}

// A column of n spheres resting on each other on the floor: body j (from 0 at the floor) is
// pushed up by the weight (n − j) m g of itself and those above, at its lowest point, and down by
// (n − j − 1) m g at its top. Love's formula over the slice of height 2r around it gives
// σ_zz = −(n − j − ½) m g / A: the weight above its centre over the cross-section A. No
// horizontal force: σ_xx = σ_yy = σ_xz = 0.
TEST(Exercise7_3, LoveStressOfAColumnIsTheWeightAboveEachCentre) {
  const int n = 4;
  const double r = 0.002;
  const grbd::scene::Scene scene = grbd::scene::parse_scene(stack_scene(n, r), "stack.toml");
  grbd::scene::Simulation sim(scene);
  sim.step();
  const double m = sim.system().inertia()[0].m;
  const double g = 9.81;
  const double A = 1e-4;  // any cross-section: σ scales with 1/A
  const Slices slices{0.0, 2.0 * r, static_cast<std::size_t>(n), A};
  const std::vector<Matrix3> sigma = grbd::scene::slice_stresses(sim, slices);
  ASSERT_EQ(sigma.size(), static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) {
    const double expected = -(n - j - 0.5) * m * g / A;
    const Matrix3& s = sigma[static_cast<std::size_t>(j)];
    EXPECT_NEAR(s(2, 2), expected, 1e-8 * std::abs(expected)) << "slice " << j;
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        if (a == 2 && b == 2) continue;
        EXPECT_NEAR(s(a, b), 0.0, 1e-8 * std::abs(expected)) << "slice " << j << ", " << a << b;
      }
    }
  }
  // One slice holding the whole column: Σ_j −(n − j − ½) m g 2r / (2 n r A) = −(n/2) m g / A.
  const std::vector<Matrix3> whole =
      grbd::scene::slice_stresses(sim, Slices{0.0, 2.0 * n * r, 1, A});
  EXPECT_NEAR(whole[0](2, 2), -0.5 * n * m * g / A, 1e-8 * n * m * g / A);
  EXPECT_THROW(grbd::scene::slice_stresses(sim, Slices{0.0, 0.0, 1, A}), InvalidArgument);
}

// The whole column in one slice of volume A · 2nr: the sum of the slices' σ V divided by it,
// −(Σ_j (n − j − ½)) m g / (A n) = −(n/2) m g / A. This is the virial of the column: Σ σ V equals
// −g Σ m_i z_i along zz for bodies at rest on a floor at z = 0.
TEST(Exercise7_3, TheWholeColumnIsTheVirialOfItsWeight) {
  const int n = 5;
  const double r = 0.0015;
  const grbd::scene::Scene scene = grbd::scene::parse_scene(stack_scene(n, r), "stack.toml");
  grbd::scene::Simulation sim(scene);
  sim.step();
  const double m = sim.system().inertia()[0].m;
  const double A = 2e-4;
  const double V = A * 2.0 * n * r;
  const std::vector<Matrix3> whole =
      grbd::scene::slice_stresses(sim, Slices{0.0, 2.0 * n * r, 1, A});
  double virial = 0.0;
  for (int j = 0; j < n; ++j) virial -= 9.81 * m * (2 * j + 1) * r;
  EXPECT_NEAR(whole[0](2, 2) * V, virial, 1e-8 * std::abs(virial));
  // Slices that miss the column measure nothing.
  const std::vector<Matrix3> above = grbd::scene::slice_stresses(sim, Slices{1.0, 0.01, 3, A});
  for (const Matrix3& s : above) EXPECT_EQ(s, Matrix3::Zero());
}

// m(t) linear with slope s_b in each of B blocks of equal duration (continuous, a transient of
// another slope before t_start): each block's slope is exactly s_b, so the error is the standard
// error of the s_b; a single line gives its slope and no error.
TEST(Exercise7_4, BlocksOfKnownSlopesGiveTheirMeanAndStandardError) {
  const std::vector<double> s = {1.0, 3.0, 2.0, 2.5, 1.5};
  const double t_start = 0.2;
  const double block = 0.1;
  std::vector<double> t, m;
  double mass = 0.0;
  for (int k = 0; k <= 700; ++k) {  // Δt = 1 ms from 0 to 0.7 s
    const double time = 1e-3 * k;
    if (k > 0) {
      const double mid = time - 0.5e-3;
      const double rate =
          mid < t_start
              ? 7.0
              : s[std::min<std::size_t>(4, static_cast<std::size_t>((mid - t_start) / block))];
      mass += rate * 1e-3;
    }
    t.push_back(time);
    m.push_back(mass);
  }
  const Rate rate = grbd::scene::steady_rate(t, m, t_start - 1e-9, 5);
  double mean = 0.0;
  for (double x : s) mean += x / 5.0;
  double var = 0.0;
  for (double x : s) var += (x - mean) * (x - mean) / 4.0;
  EXPECT_EQ(rate.blocks, 5U);
  EXPECT_NEAR(rate.error, std::sqrt(var / 5.0), 1e-9);
  // The rate is the least-squares slope of all points after t_start (not the mean of the block
  // slopes): by the normal equations, (n Σtm − Σt Σm)/(n Σt² − (Σt)²).
  double n = 0, St = 0, Sm = 0, Stm = 0, Stt = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k] < t_start - 1e-9) continue;
    n += 1;
    St += t[k];
    Sm += m[k];
    Stm += t[k] * m[k];
    Stt += t[k] * t[k];
  }
  EXPECT_NEAR(rate.rate, (n * Stm - St * Sm) / (n * Stt - St * St), 1e-9);
  EXPECT_GT(rate.rate, 1.0);
  EXPECT_LT(rate.rate, 3.0);

  std::vector<double> line(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) line[k] = 0.4 + 0.125 * t[k];
  const Rate straight = grbd::scene::steady_rate(t, line, 0.3, 4);
  EXPECT_NEAR(straight.rate, 0.125, 1e-12);
  EXPECT_NEAR(straight.error, 0.0, 1e-12);
  EXPECT_EQ(straight.blocks, 4U);
}

TEST(Exercise7_4, AUniformDischargeIsMeasuredWithinItsError) {
  // Bodies of 1 g leave at exponential intervals of mean 1 ms (a Poisson stream of 1 kg/s,
  // seeded): the steady rate lies within 4 standard errors of 1 kg/s, and the error is about
  // the Poisson one, √(rate/T) for T = 1 s, to within a factor 4.
  grbd::scene::Random random(2026);
  std::vector<double> t, m;
  double next = 0.0, mass = 0.0;
  for (int k = 0; k <= 10000; ++k) {
    const double time = 1e-4 * k;
    while (next <= time) {
      mass += 1e-3;
      next += -1e-3 * std::log(1.0 - random.uniform());
    }
    t.push_back(time);
    m.push_back(mass);
  }
  const Rate rate = grbd::scene::steady_rate(t, m, 0.0, 10);
  EXPECT_NEAR(rate.rate, 1.0, 4.0 * rate.error);
  const double poisson = std::sqrt(1.0 * 1e-3 / 1.0);
  EXPECT_GT(rate.error, poisson / 4.0);
  EXPECT_LT(rate.error, poisson * 4.0);
}

TEST(SteadyRate, RefusesSeriesItCannotMeasure) {
  const std::vector<double> t = {0, 1, 2, 3, 4, 5};
  const std::vector<double> m = {0, 1, 2, 3, 4, 5};
  EXPECT_THROW(grbd::scene::steady_rate(t, std::vector<double>{0, 1}, 0.0), InvalidArgument);
  EXPECT_THROW(grbd::scene::steady_rate(std::vector<double>{0, 1, 1, 2},
                                        std::vector<double>{0, 1, 2, 3}, 0.0, 2),
               InvalidArgument);
  EXPECT_THROW(grbd::scene::steady_rate(t, m, 0.0, 1), InvalidArgument);
  EXPECT_THROW(grbd::scene::steady_rate(t, m, 3.5, 2), InvalidArgument);  // 2 points for 2 blocks
  EXPECT_NO_THROW(grbd::scene::steady_rate(t, m, 0.0, 3));
}

// Rates made from Beverloo's law with C = 0.58, k = 1.5 and a different bulk density per orifice
// give back C and k; the rates of another law do not fit exactly.
TEST(Exercise7_5, BeverloosLawGivesBackItsCoefficients) {
  const double g = 9.81, d = 0.004;
  const std::vector<double> D = {0.020, 0.024, 0.028, 0.032};
  const std::vector<double> rho = {1450.0, 1470.0, 1440.0, 1460.0};
  std::vector<double> W;
  for (std::size_t i = 0; i < D.size(); ++i) {
    W.push_back(0.58 * rho[i] * std::sqrt(g) * std::pow(D[i] - 1.5 * d, 2.5));
  }
  const grbd::scene::BeverlooFit fit = grbd::scene::fit_beverloo(D, W, rho, g, d);
  EXPECT_NEAR(fit.C, 0.58, 1e-12);
  EXPECT_NEAR(fit.k, 1.5, 1e-10);
  EXPECT_NEAR(fit.rms, 0.0, 1e-12);
  // Two points determine the line.
  const grbd::scene::BeverlooFit two =
      grbd::scene::fit_beverloo(std::vector<double>{D[0], D[3]}, std::vector<double>{W[0], W[3]},
                                std::vector<double>{rho[0], rho[3]}, g, d);
  EXPECT_NEAR(two.C, 0.58, 1e-12);
  EXPECT_NEAR(two.k, 1.5, 1e-10);
  // W ∝ D³ is no Beverloo law: the fit leaves a residual.
  std::vector<double> cubic;
  for (double x : D) cubic.push_back(1e3 * x * x * x);
  EXPECT_GT(grbd::scene::fit_beverloo(D, cubic, rho, g, d).rms, 1e-3);
}

TEST(BeverlooFit, RefusesPointsItCannotFit) {
  const double g = 9.81, d = 0.004;
  const std::vector<double> D = {0.02, 0.03}, W = {0.1, 0.3}, rho = {1400, 1400};
  EXPECT_THROW(grbd::scene::fit_beverloo(std::vector<double>{0.02}, std::vector<double>{0.1},
                                         std::vector<double>{1400}, g, d),
               InvalidArgument);
  EXPECT_THROW(grbd::scene::fit_beverloo(D, std::vector<double>{0.1, -0.3}, rho, g, d),
               InvalidArgument);
  EXPECT_THROW(grbd::scene::fit_beverloo(std::vector<double>{0.02, 0.02}, W, rho, g, d),
               InvalidArgument);
  EXPECT_THROW(grbd::scene::fit_beverloo(D, std::vector<double>{0.3, 0.1}, rho, g, d),
               InvalidArgument);  // the rate falls as D grows
  EXPECT_THROW(grbd::scene::fit_beverloo(D, W, rho, 0.0, d), InvalidArgument);
  // W = C ρ_b √g (D − k d)^(5/2), by hand: 0.58 · 1450 · 3.13209 · 4.34691e-5 = 0.114501 kg/s.
  EXPECT_NEAR(grbd::scene::beverloo_rate(0.58, 1.5, 1450.0, 9.81, 0.024, 0.004), 0.114501, 1e-6);
  EXPECT_EQ(grbd::scene::beverloo_rate(0.58, 1.5, 1450.0, 9.81, 0.005, 0.004), 0.0);
}

// The silo of silo.toml has side walls at x = ±15 mm; the column of spheres has none.
TEST(SiloWidth, IsTheDistanceOfTheSideWalls) {
  const grbd::scene::Scene silo =
      grbd::scene::load_scene(std::string(GRBD_CH07_SCENE_DIR) + "/silo.toml");
  EXPECT_NEAR(grbd::scene::silo_width(silo), 0.030, 1e-15);
  const grbd::scene::Scene stack = grbd::scene::parse_scene(stack_scene(2, 0.001), "stack.toml");
  try {
    grbd::scene::silo_width(stack);
    ADD_FAILURE() << "a scene without side walls has no width";
  } catch (const InvalidArgument& e) {
    EXPECT_EQ(std::string(e.what()),
              "stack.toml: expected two static half-spaces with normals along x (side walls)");
  }
}

// Stresses made from Janssen's law with λ = 40 mm give λ back.
TEST(JanssenFit, StressesOfJanssensLawGiveBackTheirLength) {
  const double weight = 1350.0 * 9.81, lambda = 0.04;
  std::vector<double> depth, sigma;
  for (int k = 0; k < 20; ++k) {
    depth.push_back(0.004 * (k + 0.5));
    sigma.push_back(weight * lambda * (1.0 - std::exp(-depth.back() / lambda)));
  }
  EXPECT_NEAR(grbd::scene::fit_janssen_length(depth, sigma, weight), lambda, 1e-9);
  EXPECT_THROW(grbd::scene::fit_janssen_length(depth, sigma, 0.0), InvalidArgument);
  EXPECT_THROW(
      grbd::scene::fit_janssen_length(std::vector<double>{0.1}, std::vector<double>{1.0}, weight),
      InvalidArgument);
}

}  // namespace

namespace {

// A body system of spheres of radius 0.1 at the given centres (dynamic unless listed as fixed),
// moving at the given speeds along x.
grbd::timestep::BodySystem spheres(const std::vector<grbd::Vector3>& centres,
                                   const std::vector<bool>& fixed = {},
                                   const std::vector<double>& speed = {}) {
  grbd::timestep::BodySystem system;
  for (std::size_t i = 0; i < centres.size(); ++i) {
    grbd::timestep::BodyRecord spec;
    spec.id = i;
    spec.state.q << centres[i], 1.0, 0.0, 0.0, 0.0;
    spec.state.u.setZero();
    if (i < speed.size()) spec.state.u[0] = speed[i];
    spec.inertia.m = 1.0;
    spec.inertia.K_Theta = grbd::Vector3::Constant(0.004);
    spec.shape = grbd::collision::Sphere{0.1};
    spec.flags = i < fixed.size() && fixed[i] ? 0 : grbd::timestep::kDynamic;
    system.add(spec);
  }
  return system;
}

}  // namespace

TEST(HeapSurface, TheFlanksOfAnExactHeapGiveItsAngle) {
  // On both sides, the highest centre of each bin on z = a + b |x| with b = −tan 25°; a lower
  // body below each, and a fixed body above all (the base is left out).
  const double a = 0.3, b = -std::tan(25.0 * std::numbers::pi / 180.0);
  std::vector<grbd::Vector3> centres;
  for (int k = -4; k <= 4; ++k) {
    const double x = 0.05 + 0.1 * k;  // bin centres of width 0.1 over [−0.5, 0.5]
    centres.emplace_back(x, 0.0, a + b * std::abs(x));
    centres.emplace_back(x, 0.0, a + b * std::abs(x) - 0.2);
  }
  centres.emplace_back(0.25, 0.0, 5.0);
  std::vector<bool> fixed(centres.size(), false);
  fixed.back() = true;
  const auto system = spheres(centres, fixed);
  const grbd::scene::HeapSurface surface = grbd::scene::heap_surface(system, 0.5, 0.1);
  ASSERT_EQ(surface.x.size(), 10U);
  EXPECT_EQ(surface.top[0], 0.0);  // the bin [−0.5, −0.4) holds nothing
  const grbd::scene::FlankFit fit = grbd::scene::fit_flanks(surface, 0.1, 0.5);
  EXPECT_EQ(fit.bins, 7U);  // 9 bins hold bodies; the two at |x| = 0.05 are left out
  EXPECT_NEAR(fit.a, a, 1e-12);
  EXPECT_NEAR(fit.b, b, 1e-12);
  EXPECT_NEAR(fit.angle, 25.0, 1e-10);
  EXPECT_LT(fit.angle_error, 1e-9);
  EXPECT_LT(fit.rms, 1e-12);
}

TEST(HeapSurface, ScatterGivesTheLeastSquaresStandardError) {
  // One flank, |x| = 1.5 … 5.5, with residuals δ (1, −2, 0, 2, −1): orthogonal to 1 and to |x|,
  // so the line is unchanged, and Σ residual² = 10 δ², Σ(r − r̄)² = 10: the standard error of
  // the slope is √(10 δ²/3 / 10) = δ/√3, that of the angle δ/√3/(1 + b²).
  const double a = 4.0, b = -0.5, delta = 0.01;
  const double e[] = {1.0, -2.0, 0.0, 2.0, -1.0};
  std::vector<grbd::Vector3> centres;
  for (int k = 0; k < 5; ++k) {
    const double r = 1.5 + k;
    centres.emplace_back(r, 0.0, a + b * r + delta * e[k]);
  }
  const auto fit = grbd::scene::fit_flanks(grbd::scene::heap_surface(spheres(centres), 6.0, 1.0),
                                           1.0, 6.0);
  EXPECT_EQ(fit.bins, 5U);
  EXPECT_NEAR(fit.b, b, 1e-12);
  EXPECT_NEAR(fit.rms, delta * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(fit.angle_error, delta / std::sqrt(3.0) / 1.25 * 180.0 / std::numbers::pi, 1e-10);
  // Too few bins, and a bad window, are refused.
  EXPECT_THROW(grbd::scene::fit_flanks(grbd::scene::heap_surface(spheres(centres), 6.0, 1.0), 4.0,
                                       5.0),
               InvalidArgument);
  EXPECT_THROW(grbd::scene::heap_surface(spheres(centres), 1.0, 3.0), InvalidArgument);
}

TEST(AtRest, EveryDynamicBodyBelowTheSpeed) {
  // A fixed body's velocity does not count (it never moves).
  const auto system = spheres({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {false, false, true},
                              {0.0, 0.002, 0.5});
  EXPECT_EQ(grbd::scene::max_speed(system), 0.002);
  EXPECT_FALSE(grbd::scene::at_rest(system, 0.001));
  EXPECT_TRUE(grbd::scene::at_rest(system, 0.003));
}
