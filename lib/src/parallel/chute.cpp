/// \file
/// \brief The chute's frames, the front and the flow times.

#include "grbd/parallel/chute.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd/io/output.hpp"

namespace grbd::parallel {

Vector3 ChuteGeometry::runout(const Vector3& position) const {
  const double a = bend_degrees * std::numbers::pi / 180.0;
  const Vector3 along(std::cos(a), 0.0, -std::sin(a));  // the upper chute's x turned by the bend
  const Vector3 normal(std::sin(a), 0.0, std::cos(a));
  const Vector3 d = position - Vector3(kink_x, 0.0, 0.0);
  return Vector3(d.dot(along), position.y(), d.dot(normal));
}

double ChuteGeometry::path(const Vector3& position) const {
  if (position.x() >= kink_x) return -position.x();
  return -kink_x - runout(position).x();
}

double front(std::span<const Vector3> centres, const ChuteGeometry& chute) {
  if (centres.empty()) return 0.0;
  std::vector<double> s(centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) s[i] = chute.path(centres[i]);
  const std::size_t ahead = centres.size() / 1000;  // beads allowed ahead of the front
  std::nth_element(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(ahead), s.end(),
                   std::greater<>());
  return s[ahead];
}

VelocityField velocity_field(const CameraGrid& camera, const ChuteGeometry& chute,
                             std::span<const Vector3> centres,
                             std::span<const Vector3> velocities) {
  if (centres.size() != velocities.size()) {
    throw InvalidArgument("velocity_field: expected one velocity per centre, found " +
                          std::to_string(velocities.size()) + " for " +
                          std::to_string(centres.size()));
  }
  if (camera.columns < 1 || camera.rows < 1) {
    throw InvalidArgument("velocity_field: expected a camera grid of at least one pixel, found " +
                          std::to_string(camera.columns) + " × " + std::to_string(camera.rows));
  }
  require_positive_finite("velocity_field", "pixels_per_metre", camera.pixels_per_metre);
  VelocityField field{camera, {}, {}, {}};
  const auto n = static_cast<std::size_t>(camera.columns) * static_cast<std::size_t>(camera.rows);
  field.along.assign(n, 0.0);
  field.across.assign(n, 0.0);
  field.count.assign(n, 0);
  // A velocity in the run-out's frame: the frame's map less its origin (a rotation).
  const Vector3 origin = chute.runout(Vector3::Zero());
  for (std::size_t i = 0; i < centres.size(); ++i) {
    const auto pixel = pixel_of(camera, chute, centres[i]);
    if (!pixel) continue;
    const std::size_t k =
        static_cast<std::size_t>((*pixel)[1]) * static_cast<std::size_t>(camera.columns) +
        static_cast<std::size_t>((*pixel)[0]);
    const Vector3 v = chute.runout(velocities[i]) - origin;
    field.along[k] -= v.x();  // downstream is −x'
    field.across[k] += v.y();
    ++field.count[k];
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (field.count[k] == 0) continue;
    field.along[k] /= field.count[k];
    field.across[k] /= field.count[k];
  }
  return field;
}

std::optional<double> FlowTimes::duration() const {
  if (first && last) return *last - *first;
  return std::nullopt;
}

namespace {

// The first time the sampled count reaches `level`, interpolated linearly.
std::optional<double> reaches(std::span<const double> t, std::span<const double> count,
                              double level) {
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (count[k] < level) continue;
    if (k == 0 || count[k] == count[k - 1]) return t[k];
    const double w = (level - count[k - 1]) / (count[k] - count[k - 1]);
    return t[k - 1] + std::max(0.0, w) * (t[k] - t[k - 1]);
  }
  return std::nullopt;
}

}  // namespace

FlowTimes flow_times(std::span<const double> t, std::span<const double> count, double beads,
                     double entry_count) {
  if (t.size() != count.size()) {
    throw InvalidArgument("flow_times: expected one count per time, found " +
                          std::to_string(count.size()) + " for " + std::to_string(t.size()));
  }
  require_positive_finite("flow_times", "beads", beads);
  require_positive_finite("flow_times", "entry_count", entry_count);
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (!std::isfinite(t[k]) || (k > 0 && !(t[k] > t[k - 1]))) {
      throw InvalidArgument("flow_times: expected finite, increasing times, found t[" +
                            std::to_string(k) + "] = " + format_number(t[k]));
    }
    if (!(count[k] >= 0.0 && count[k] <= beads)) {
      throw InvalidArgument("flow_times: expected counts in [0, " + format_number(beads) +
                            "], found " + format_number(count[k]) +
                            " at t = " + format_number(t[k]) + " s");
    }
  }
  return {reaches(t, count, entry_count), reaches(t, count, 0.01 * beads),
          reaches(t, count, 0.95 * beads)};
}

FlowSeries flow_series(const std::filesystem::path& output, const ChuteGeometry& chute) {
  const std::string file = output.string();
  const io::OutputSummary summary = io::read_summary(output);
  if (summary.records == 0) throw io::IoError(file + ": holds no record");
  FlowSeries series;
  std::vector<Vector3> centres;
  for (std::uint64_t k = 0; k < summary.records; ++k) {
    const io::Record record = io::read_record(output, k);
    centres.clear();
    for (const body::State& x : record.states) centres.push_back(x.q.head<3>());
    if (k == 0) series.beads = static_cast<double>(centres.size());
    const double removed = std::max(0.0, series.beads - static_cast<double>(centres.size()));
    series.t.push_back(record.t);
    series.bodies.push_back(static_cast<double>(centres.size()));
    series.count.push_back(static_cast<double>(flow_count(centres, chute)) + removed);
    series.front.push_back(front(centres, chute));
  }
  if (!(series.beads > 0.0)) throw io::IoError(file + ": the first record holds no bead");
  return series;
}

}  // namespace grbd::parallel
