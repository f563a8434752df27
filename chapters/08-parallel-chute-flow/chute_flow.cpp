// Chapter 8 demo: what a run of the reference chute did, read from its output file.
//
// README command (1) runs chute.toml under mpiexec (chapters/08-parallel-chute-flow/CMakeLists.txt)
// and hands its output to this program, which measures, record by record, the flow count F(t) past
// the kink and the front (parallel::flow_series), the flow's times (parallel::flow_times), the
// front's speed, and the plan-view velocity field on the experiment's camera grid at three moments
// of the flow — the records nearest where 10 %, 50 % and 90 % of the beads have passed the kink,
// each field averaged over that record and its two neighbours in windows of 2 × 2 camera pixels,
// as image velocimetry averages over interrogation windows — and, step by step, the contacts, the
// solver's sweeps and the largest penetration.
//
// Output in the data directory: flow.csv (t, t after the release, beads left, F, front, front
// speed), steps.csv (t, contacts, sweeps, converged, residual, largest penetration in mm),
// field<k>.dat (k = 1, 2, 3: downstream distance from the kink and y' in cm, mean speed along and
// across in m/s, beads counted; blank lines between rows, for gnuplot's image plot), trees.dat (the
// trees' axes where they cross the run-out's floor, in cm) and values.txt (the numbers the chapter
// quotes).
//
// Usage: `ch08_chute <data directory> <scene.toml> <output.h5>`.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "grbd/io/output.hpp"
#include "grbd/parallel/chute.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd_demo/demo.hpp"

namespace {

namespace par = grbd::parallel;
using grbd::Vector3;

constexpr const char* kProgram = "ch08_chute";

// The release: the time from which the scene's gate (the static object with `until`) is gone.
double release_time(const grbd::scene::Scene& scene) {
  for (const auto& s : scene.statics) {
    if (s.until) return *s.until;
  }
  throw grbd::Error(scene.file.string() + ": no static object with `until` (a gate) to release");
}

// The run-out's length to the outlet: where the domain's end x_min lies along the run-out's floor.
double outlet_runout(const grbd::scene::Scene& scene, const par::ChuteGeometry& chute) {
  if (!scene.domain.enabled) throw grbd::Error(scene.file.string() + ": no outlet (domain)");
  const double a = chute.bend_degrees * std::numbers::pi / 180.0;
  return (chute.kink_x - scene.domain.box.min.x()) / std::cos(a);
}

// The index of the record at which F first reaches `fraction` of the beads (the last if never).
std::size_t record_at(const par::FlowSeries& series, double fraction) {
  for (std::size_t k = 0; k < series.t.size(); ++k) {
    if (series.count[k] >= fraction * series.beads) return k;
  }
  return series.t.size() - 1;
}

// The velocity field of records first..last (inclusive), pixel by pixel the mean over every bead
// seen there in any of them.
par::VelocityField averaged_field(const std::filesystem::path& output,
                                  const par::CameraGrid& camera, const par::ChuteGeometry& chute,
                                  std::size_t first, std::size_t last) {
  par::VelocityField sum{camera, {}, {}, {}};
  std::vector<Vector3> centres, velocities;
  for (std::size_t k = first; k <= last; ++k) {
    const grbd::io::Record record = grbd::io::read_record(output, k);
    centres.clear();
    velocities.clear();
    for (const grbd::body::State& x : record.states) {
      centres.push_back(x.q.head<3>());
      velocities.push_back(x.u.head<3>());
    }
    const par::VelocityField field = par::velocity_field(camera, chute, centres, velocities);
    if (sum.count.empty()) {
      sum.along.assign(field.along.size(), 0.0);
      sum.across.assign(field.across.size(), 0.0);
      sum.count.assign(field.count.size(), 0);
    }
    for (std::size_t p = 0; p < field.count.size(); ++p) {
      sum.along[p] += field.along[p] * field.count[p];
      sum.across[p] += field.across[p] * field.count[p];
      sum.count[p] += field.count[p];
    }
  }
  for (std::size_t p = 0; p < sum.count.size(); ++p) {
    if (sum.count[p] == 0) continue;
    sum.along[p] /= sum.count[p];
    sum.across[p] /= sum.count[p];
  }
  return sum;
}

void run(const std::filesystem::path& dir, const std::filesystem::path& scene_file,
         const std::filesystem::path& output) {
  const grbd::scene::Scene scene = grbd::scene::load_scene(scene_file);
  const double release = release_time(scene);
  const par::ChuteGeometry chute;
  const par::FlowSeries series = par::flow_series(output, chute);
  const par::FlowTimes times = par::flow_times(series.t, series.count, series.beads);
  const std::size_t n = series.t.size();

  // The front's speed: central differences of the front between records.
  std::vector<double> speed(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t a = k == 0 ? 0 : k - 1, b = std::min(k + 1, n - 1);
    if (b > a) speed[k] = (series.front[b] - series.front[a]) / (series.t[b] - series.t[a]);
  }
  grbd::demo::OutputFile flow(dir / "flow.csv",
                              "t_s,t_release_s,beads,flow_count,front_m,front_m_s");
  for (std::size_t k = 0; k < n; ++k) {
    flow << series.t[k] << ',' << series.t[k] - release << ',' << series.bodies[k] << ','
         << series.count[k] << ',' << series.front[k] << ',' << speed[k] << '\n';
  }
  flow.finish();
  // The front's mean speed over the run-out's first 0.3 m, from the records on either side.
  const double kink = -chute.kink_x;
  std::size_t a = n, b = n;
  for (std::size_t k = 0; k < n; ++k) {
    if (a == n && series.front[k] >= kink) a = k;
    if (b == n && series.front[k] >= kink + 0.3) b = k;
  }
  const double runout_speed =
      a < n && b < n && b > a ? (series.front[b] - series.front[a]) / (series.t[b] - series.t[a])
                              : 0.0;
  double fastest = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    if (series.t[k] > release) fastest = std::max(fastest, speed[k]);
  }

  // Step by step: contacts, sweeps, penetration.
  const std::vector<grbd::io::StepInfo> steps = grbd::io::read_steps(output);
  grbd::demo::OutputFile table(dir / "steps.csv",
                               "t_s,contacts,sweeps,converged,residual,max_penetration_mm,"
                               "mean_penetration_mm");
  double penetration = 0.0, sweeps = 0.0, seconds = 0.0, mean_penetration = 0.0, weight = 0.0;
  std::size_t capped = 0, contacts = 0;
  const int cap = scene.settings.solver.max_iterations;
  for (const auto& s : steps) {
    table << s.t << ',' << s.contacts << ',' << s.iterations << ',' << (s.converged ? 1 : 0) << ','
          << s.residual << ',' << s.max_penetration * 1e3 << ',' << s.mean_penetration * 1e3
          << '\n';
    penetration = std::max(penetration, s.max_penetration);
    // The mean over every contact of every step: each step's mean weighted by its contacts.
    mean_penetration += s.mean_penetration * static_cast<double>(s.contacts);
    weight += static_cast<double>(s.contacts);
    sweeps += s.iterations;
    seconds += s.seconds;
    capped += s.iterations >= cap ? 1 : 0;
    contacts = std::max<std::size_t>(contacts, s.contacts);
  }
  table.finish();
  if (steps.empty()) throw grbd::Error(output.string() + ": holds no step");

  // The velocity field at three moments, in windows of 2 × 2 camera pixels over the channel.
  par::CameraGrid camera;
  camera.pixels_per_metre /= 2.0;
  const double half_width = 0.05;  // rows over |y'| < 5 cm: the channel and a margin
  camera.rows = static_cast<int>(std::ceil(2.0 * half_width * camera.pixels_per_metre));
  camera.y0 = -0.5 * camera.rows / camera.pixels_per_metre;
  camera.columns = static_cast<int>(std::ceil(0.62 * camera.pixels_per_metre));
  grbd::demo::Values values;
  const double fractions[3] = {0.1, 0.5, 0.9};
  for (int f = 0; f < 3; ++f) {
    const std::size_t k = record_at(series, fractions[f]);
    const std::size_t first = k == 0 ? 0 : k - 1, last = std::min(k + 1, n - 1);
    const par::VelocityField field = averaged_field(output, camera, chute, first, last);
    grbd::demo::OutputFile out(dir / ("field" + std::to_string(f + 1) + ".dat"),
                               "# x_cm y_cm along_m_s across_m_s beads");
    const double s = camera.pixels_per_metre;
    for (int j = 0; j < camera.rows; ++j) {
      for (int i = 0; i < camera.columns; ++i) {
        const std::size_t p = static_cast<std::size_t>(j) * camera.columns + i;
        const double x = 100.0 * (-camera.x0 + (i + 0.5) / s);
        const double y = 100.0 * (camera.y0 + (j + 0.5) / s);
        if (field.count[p] == 0) {
          out << x << ' ' << y << " NaN NaN 0\n";
        } else {
          out << x << ' ' << y << ' ' << field.along[p] << ' ' << field.across[p] << ' '
              << field.count[p] << '\n';
        }
      }
      out << '\n';
    }
    out.finish();
    const std::string key = "field" + std::to_string(f + 1) + ".";
    values.set(key + "percent", "%.0f", 100.0 * fractions[f]);
    values.set(key + "t", "%.2f", series.t[k]);
    values.set(key + "after", "%.2f", series.t[k] - release);
  }

  // The trees where their axes cross the run-out's floor (downstream distance, y') [cm].
  grbd::demo::OutputFile trees(dir / "trees.dat", "# x_cm y_cm radius_cm");
  double first_tree = 1e9;
  for (const auto& s : scene.statics) {
    const auto* capsule = std::get_if<grbd::collision::Capsule>(&s.shape);
    if (capsule == nullptr) continue;
    const Vector3 axis = s.pose.A_IC.col(2);
    const Vector3 c = chute.runout(s.pose.I_r),
                  e = chute.runout(s.pose.I_r + axis) - chute.runout(Vector3::Zero());
    const Vector3 foot = c - e * (c.z() / e.z());
    trees << -100.0 * foot.x() << ' ' << 100.0 * foot.y() << ' ' << 100.0 * capsule->radius << '\n';
    first_tree = std::min(first_tree, -foot.x());
  }
  trees.finish();

  const auto put = [&](const char* key, const std::optional<double>& t) {
    if (t) {
      values.set(key, "%.3f", *t);
    } else {
      values.set(key, "%s", "never");
    }
  };
  values.set("first_tree_cm", "%.1f", 100.0 * first_tree);
  values.set("kink_m", "%.3f", kink);
  values.set("outlet_m", "%.3f", kink + outlet_runout(scene, chute));
  values.set("beads", "%.0f", series.beads);
  values.set("release", "%.2f", release);
  values.set("records", "%zu", n);
  values.set("end", "%.2f", series.t.back());
  put("entry", times.entry);
  put("first", times.first);
  put("last", times.last);
  put("duration", times.duration());
  if (times.entry) values.set("entry_after_release", "%.3f", *times.entry - release);
  if (times.entry && times.last) values.set("entry_to_last", "%.3f", *times.last - *times.entry);
  values.set("past_percent", "%.1f", 100.0 * series.count.back() / series.beads);
  values.set("left", "%.0f", series.bodies.back());
  values.set("runout_speed", "%.2f", runout_speed);
  values.set("fastest_front", "%.2f", fastest);
  values.set("max_penetration_mm", "%.2f", penetration * 1e3);
  values.set("mean_penetration_um", "%.1f", weight > 0.0 ? 1e6 * mean_penetration / weight : 0.0);
  // The 99th percentile of the overlaps at the records (their distributions, chapter 6's
  // OverlapHistogram): the upper edge of its bin.
  values.set("p99_penetration_um", "%.1f",
             1e6 * grbd::io::read_summary(output).accuracy.p99_overlap());
  values.set("min_radius_mm", "%.2f", scene.groups.front().radius.min() * 1e3);
  values.set("max_penetration_percent", "%.0f",
             100.0 * penetration / scene.groups.front().radius.min());
  values.set("mean_sweeps", "%.0f", sweeps / static_cast<double>(steps.size()));
  values.set("capped_percent", "%.0f", 100.0 * capped / static_cast<double>(steps.size()));
  values.set("cap", "%d", cap);
  values.set("max_contacts", "%zu", contacts);
  values.set("steps", "%zu", steps.size());
  values.write(dir / "values.txt");
  std::printf("%s: %.0f beads, entry %.3f s, 1 %% → 95 %% %.3f s, %.0f sweeps a step, %.0f s\n",
              kProgram, series.beads, times.entry.value_or(NAN), times.duration().value_or(NAN),
              sweeps / static_cast<double>(steps.size()), seconds);
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto code = grbd::demo::check_arguments(
          argc, argv, kProgram, {"<data directory>", "<scene.toml>", "<output.h5>"},
          "writes flow.csv, steps.csv, field1-3.dat, trees.dat and values.txt: the flow count, "
          "the front, the velocity fields and the solver's work of a run of the reference chute",
          3, 3)) {
    return *code;
  }
  try {
    run(argv[1], argv[2], argv[3]);
    return 0;
  } catch (...) {
    return grbd::demo::report_exception(kProgram, "the chapter 8 chute study");
  }
}
