// Scene files (chapter 7): TOML read with toml++ into a checked Scene.
//
// Every table is read through a TableReader, which records the keys it was asked for; when the
// table is done, any other key is an error that suggests the closest known one. Every value is
// checked where it is read, so that the message can name the file, the line and column, the
// full key ("bodies[2].radius.min"), what was expected and what was found.

#include <toml++/toml.h>
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <set>
#include <sstream>

#include "grbd/body/triangle_mesh.hpp"
#include "grbd/collision/static_mesh.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/kinematics/exponential.hpp"
#include "grbd/kinematics/rotation.hpp"
#include "grbd/scene/scene.hpp"
#include "grbd/timestep/materials.hpp"

namespace grbd::scene {

std::string_view generator_name(GeneratorKind kind) {
  switch (kind) {
    case GeneratorKind::list:
      return "list";
    case GeneratorKind::lattice:
      return "lattice";
    case GeneratorKind::packing:
      return "packing";
    case GeneratorKind::inflow:
      return "inflow";
  }
  return "?";
}

std::uint64_t Scene::steps() const {
  return static_cast<std::uint64_t>(std::llround(end_time / settings.dt));
}

void set_end_time(Scene& scene, double end_time, std::string_view source) {
  if (!(end_time > 0.0) || !std::isfinite(end_time)) {
    throw SceneError(std::string(source) + ": expected a time > 0 s, found " +
                     format_number(end_time));
  }
  if (end_time / scene.settings.dt > static_cast<double>(kMaxSteps)) {
    throw SceneError(std::string(source) +
                     ": expected at most 10¹² steps of dt = " + format_number(scene.settings.dt) +
                     " s, found " + format_number(end_time) + " s");
  }
  scene.end_time = end_time;
}

double parse_real(std::string_view text, std::string_view source) {
  double value = 0.0;
  const char* first = text.data();
  const char* last = first + text.size();
  // from_chars takes no leading '+' and, in the general format, no hexadecimal; "inf" and "nan"
  // it does take, and they are refused below.
  const auto [end, error] = std::from_chars(first, last, value, std::chars_format::general);
  if (text.empty() || error != std::errc() || end != last || !std::isfinite(value)) {
    throw SceneError(std::string(source) +
                     ": expected a decimal number such as 0.5 or 2e-3, found \"" +
                     std::string(text) + "\"");
  }
  return value;
}

std::string closest_key(std::string_view key, const std::vector<std::string_view>& known) {
  // Levenshtein distance by one row of the dynamic programme.
  auto distance = [](std::string_view a, std::string_view b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      std::size_t diagonal = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j) {
        const std::size_t up = row[j];
        const std::size_t substitute = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitute});
        diagonal = up;
      }
    }
    return row[b.size()];
  };
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(1, key.size() / 2) + 1;
  for (std::string_view candidate : known) {
    const std::size_t d = distance(key, candidate);
    if (d < best_distance) {
      best_distance = d;
      best = std::string(candidate);
    }
  }
  return best;
}

namespace {

// "a number 3.5", "a string \"abc\"", "a table", … : what a node is, for "found …".
std::string describe(const toml::node& node) {
  std::ostringstream out;
  if (const auto* v = node.as_floating_point()) {
    out << "the number " << v->get();
  } else if (const auto* i = node.as_integer()) {
    out << "the integer " << i->get();
  } else if (const auto* s = node.as_string()) {
    std::string text = s->get();
    if (text.size() > 40) text = text.substr(0, 40) + "…";
    out << "the string \"";
    for (const char c : text) {  // control characters (a NUL) as TOML escapes, never raw
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
        char escape[8];
        std::snprintf(escape, sizeof(escape), "\\u%04x", static_cast<unsigned>(c));
        out << escape;
      } else {
        out << c;
      }
    }
    out << "\"";
  } else if (const auto* b = node.as_boolean()) {
    out << (b->get() ? "true" : "false");
  } else if (const auto* a = node.as_array()) {
    out << "an array of " << a->size() << (a->size() == 1 ? " element" : " elements");
  } else if (node.is_table()) {
    out << "a table";
  } else {
    out << "a date or time";
  }
  return out.str();
}

std::string position(const std::string& file, const toml::source_region& where) {
  std::ostringstream out;
  out << file;
  if (where.begin.line > 0) out << ':' << where.begin.line << ':' << where.begin.column;
  return out.str();
}

// A range that a number must lie in; the text is what the message says was expected.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;
  bool contains(double x) const {
    return std::isfinite(x) && (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  }
  std::string text() const {
    std::ostringstream out;
    const bool has_lo = std::isfinite(lo);
    const bool has_hi = std::isfinite(hi);
    if (has_lo && has_hi) {
      out << "a number in " << (lo_open ? "(" : "[") << lo << ", " << hi << (hi_open ? ")" : "]");
    } else if (has_lo) {
      out << "a number " << (lo_open ? "> " : "≥ ") << lo;
    } else if (has_hi) {
      out << "a number " << (hi_open ? "< " : "≤ ") << hi;
    } else {
      out << "a finite number";
    }
    return out.str();
  }
};
const Range kAny{};
const Range kPositive{0.0, std::numeric_limits<double>::infinity(), true, false};
const Range kNonNegative{0.0, std::numeric_limits<double>::infinity(), false, false};
const Range kUnit{0.0, 1.0, false, false};

// Reads one table: every key asked for is known; finish() refuses the others.
class TableReader {
 public:
  TableReader(const toml::table& table, std::string path, const std::string& file)
      : table_(table), path_(std::move(path)), file_(file) {}

  const toml::table& table() const { return table_; }
  const std::string& path() const { return path_; }
  std::string key_path(std::string_view key) const {
    if (key.empty()) return path_;
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }

  // The node of `key`, or nullptr; marks the key as known.
  const toml::node* get(std::string_view key) {
    known_.push_back(key);
    return table_.get(key);
  }
  bool has(std::string_view key) { return get(key) != nullptr; }

  [[noreturn]] void fail_at(const toml::source_region& where, std::string_view key,
                            std::string_view expected, std::string_view found) const {
    std::ostringstream out;
    out << position(file_, where) << ": " << key_path(key) << ": expected " << expected;
    if (!found.empty()) out << ", found " << found;
    throw SceneError(out.str());
  }
  [[noreturn]] void fail(const toml::node& node, std::string_view key,
                         std::string_view expected) const {
    fail_at(node.source(), key, expected, describe(node));
  }
  [[noreturn]] void missing(std::string_view key, std::string_view expected) const {
    // A misspelt key explains a missing one better than "required".
    for (const auto& [name, node] : table_) {
      if (std::find(known_.begin(), known_.end(), name.str()) == known_.end() &&
          !closest_key(name.str(), {key}).empty()) {
        unknown(name, key);
      }
    }
    fail_at(table_.source(), key, expected, "nothing (the key is required)");
  }
  // "Exactly one of `keys`" found neither of them: a key of the table that was not asked for and
  // is close to one of them is a misspelling, which explains the absence better, at its line.
  [[noreturn]] void neither(std::vector<std::string_view> keys, std::string_view key,
                            std::string_view expected) const {
    for (const auto& [name, node] : table_) {
      if (std::find(known_.begin(), known_.end(), name.str()) != known_.end()) continue;
      const std::string near = closest_key(name.str(), keys);
      if (!near.empty()) unknown(name, near);
    }
    fail_at(table_.source(), key, expected, "neither");
  }
  [[noreturn]] void unknown(const toml::key& key, std::string_view near) const {
    std::ostringstream out;
    out << position(file_, key.source()) << ": " << key_path(key.str()) << ": unknown key";
    if (!near.empty()) {
      out << " (did you mean \"" << near << "\"?)";
    } else {
      out << "; the keys of " << (path_.empty() ? std::string("the top level") : path_) << " are:";
      std::set<std::string_view> sorted(known_.begin(), known_.end());
      for (std::string_view k : sorted) out << ' ' << k;
    }
    throw SceneError(out.str());
  }

  std::optional<double> real_opt(std::string_view key, const Range& range = kAny) {
    const toml::node* node = get(key);
    if (node == nullptr) return std::nullopt;
    return to_real(*node, key, range);
  }
  double real(std::string_view key, double fallback, const Range& range = kAny) {
    return real_opt(key, range).value_or(fallback);
  }
  double real_required(std::string_view key, const Range& range = kAny) {
    const auto value = real_opt(key, range);
    if (!value) missing(key, range.text());
    return *value;
  }
  double to_real(const toml::node& node, std::string_view key, const Range& range) const {
    return to_real_element(node, key, range.text(), range);
  }

  std::int64_t integer(std::string_view key, std::int64_t fallback, std::int64_t lo,
                       std::int64_t hi) {
    const toml::node* node = get(key);
    if (node == nullptr) return fallback;
    std::ostringstream expected;
    expected << "an integer in [" << lo << ", " << hi << "]";
    const auto* i = node->as_integer();
    if (i == nullptr || i->get() < lo || i->get() > hi) fail(*node, key, expected.str());
    return i->get();
  }

  bool boolean(std::string_view key, bool fallback) {
    const toml::node* node = get(key);
    if (node == nullptr) return fallback;
    const auto* b = node->as_boolean();
    if (b == nullptr) fail(*node, key, "true or false");
    return b->get();
  }

  std::optional<std::string> string_opt(std::string_view key) {
    const toml::node* node = get(key);
    if (node == nullptr) return std::nullopt;
    const auto* s = node->as_string();
    if (s == nullptr || s->get().empty()) fail(*node, key, "a non-empty string");
    return s->get();
  }
  std::string string_required(std::string_view key, std::string_view what) {
    auto value = string_opt(key);
    if (!value) missing(key, what);
    return *value;
  }
  // A file name: a non-empty string without NUL (the system would cut the name there and open
  // another file).
  std::optional<std::string> file_name_opt(std::string_view key) {
    auto value = string_opt(key);
    if (value && value->find('\0') != std::string::npos) {
      fail(*get(key), key, "a file name without NUL characters");
    }
    return value;
  }

  // One of `choices`; returns its index (`fallback` when the key is absent).
  std::size_t choice(std::string_view key, const std::vector<std::string_view>& choices,
                     std::optional<std::size_t> fallback) {
    const toml::node* node = get(key);
    std::string expected = "one of";
    for (std::size_t k = 0; k < choices.size(); ++k) {
      expected += (k == 0 ? " \"" : ", \"") + std::string(choices[k]) + "\"";
    }
    if (node == nullptr) {
      if (!fallback) missing(key, expected);
      return *fallback;
    }
    const auto* s = node->as_string();
    if (s != nullptr) {
      for (std::size_t k = 0; k < choices.size(); ++k) {
        if (s->get() == choices[k]) return k;
      }
      const std::string near = closest_key(s->get(), choices);
      if (!near.empty()) expected += " (did you mean \"" + near + "\"?)";
    }
    fail(*node, key, expected);
  }

  std::optional<Vector3> vector_opt(std::string_view key, const Range& range = kAny) {
    const toml::node* node = get(key);
    if (node == nullptr) return std::nullopt;
    return to_vector3(*node, key, range);
  }
  Vector3 vector(std::string_view key, const Vector3& fallback, const Range& range = kAny) {
    return vector_opt(key, range).value_or(fallback);
  }
  Vector3 vector_required(std::string_view key, const Range& range = kAny) {
    auto value = vector_opt(key, range);
    if (!value) missing(key, "an array of 3 numbers");
    return *value;
  }
  Vector3 to_vector3(const toml::node& node, std::string_view key, const Range& range) const {
    const std::string expected =
        "an array of 3 numbers" + (&range == &kAny ? std::string() : ", each " + range.text());
    const auto* a = node.as_array();
    if (a == nullptr || a->size() != 3) fail(node, key, expected);
    Vector3 v;
    for (int k = 0; k < 3; ++k) {
      v[k] = to_real_element(*a->get(static_cast<std::size_t>(k)), key, expected, range);
    }
    return v;
  }

  // An array of numbers (at least `min_size`), each in `range`.
  std::vector<double> reals(std::string_view key, std::size_t min_size, const Range& range) {
    const toml::node* node = get(key);
    std::ostringstream expected;
    expected << "an array of at least " << min_size << " numbers, each " << range.text();
    if (node == nullptr) missing(key, expected.str());
    const auto* a = node->as_array();
    if (a == nullptr || a->size() < min_size) fail(*node, key, expected.str());
    std::vector<double> out;
    for (const toml::node& x : *a) out.push_back(to_real_element(x, key, expected.str(), range));
    return out;
  }
  // A number (an integer is taken as one) in `range`; else fails with `expected`.
  double to_real_element(const toml::node& x, std::string_view key, const std::string& expected,
                         const Range& range) const {
    if (!x.is_number()) fail(x, key, expected);
    const double value =
        x.is_integer() ? static_cast<double>(*x.value<std::int64_t>()) : *x.value<double>();
    if (!range.contains(value)) fail(x, key, expected);
    return value;
  }

  // A sub-table, or nullptr.
  const toml::table* table_opt(std::string_view key) {
    const toml::node* node = get(key);
    if (node == nullptr) return nullptr;
    if (!node->is_table()) fail(*node, key, "a table");
    return node->as_table();
  }
  // An array of tables ([[key]]), or nullptr.
  const toml::array* tables_opt(std::string_view key) {
    const toml::node* node = get(key);
    if (node == nullptr) return nullptr;
    const auto* a = node->as_array();
    if (a == nullptr || !a->is_array_of_tables())
      fail(*node, key, "an array of tables ([[" + std::string(key) + "]])");
    return a;
  }

  // Refuses every key that was not asked for, suggesting the closest known one.
  void finish() const {
    for (const auto& [key, node] : table_) {
      if (std::find(known_.begin(), known_.end(), key.str()) != known_.end()) continue;
      unknown(key, closest_key(key.str(), known_));
    }
  }

  const std::string& file() const { return file_; }

 private:
  const toml::table& table_;
  std::string path_;
  const std::string& file_;
  std::vector<std::string_view> known_;
};

std::string indexed(std::string_view name, std::size_t k) {
  return std::string(name) + "[" + std::to_string(k) + "]";
}

// A radius: a number, or a table { distribution = …, … }.
RadiusDistribution read_radius(TableReader& reader, std::string_view key) {
  const toml::node* node = reader.get(key);
  const std::string expected =
      "a radius > 0 or a table { distribution = \"fixed\", \"uniform\", \"normal\" or "
      "\"piecewise\", … }";
  if (node == nullptr) reader.missing(key, expected);
  if (node->is_number()) return RadiusDistribution::fixed(reader.to_real(*node, key, kPositive));
  if (!node->is_table()) reader.fail(*node, key, expected);
  TableReader t(*node->as_table(), reader.key_path(key), reader.file());
  const std::size_t kind =
      t.choice("distribution", {"fixed", "uniform", "normal", "piecewise"}, std::nullopt);
  RadiusDistribution result = RadiusDistribution::fixed(1.0);
  try {
    switch (kind) {
      case 0:
        result = RadiusDistribution::fixed(t.real_required("radius", kPositive));
        break;
      case 1: {
        const double lo = t.real_required("min", kPositive);
        const double hi = t.real_required("max", kPositive);
        result = RadiusDistribution::uniform(lo, hi);
        break;
      }
      case 2: {
        const double mean = t.real_required("mean", kPositive);
        const double sd = t.real_required("std", kPositive);
        const double lo = t.real_required("min", kPositive);
        const double hi = t.real_required("max", kPositive);
        result = RadiusDistribution::truncated_normal(mean, sd, lo, hi);
        break;
      }
      default: {
        std::vector<double> edges = t.reals("edges", 2, kPositive);
        std::vector<double> densities = t.reals("densities", 1, kNonNegative);
        result = RadiusDistribution::piecewise_constant(std::move(edges), std::move(densities));
        break;
      }
    }
  } catch (const SceneError&) {
    throw;
  } catch (const InvalidArgument& e) {
    // The factory's own check (e.g. min > max): name the table.
    t.fail_at(node->source(), "", "a valid distribution", e.what());
  }
  t.finish();
  return result;
}

// An orientation: `orientation = [p0, p1, p2, p3]` (a unit quaternion, scalar first) or
// `rotation = [x, y, z, degrees]` (axis and angle); the identity without either.
kinematics::Quaternion read_orientation(TableReader& reader) {
  const toml::node* quaternion = reader.get("orientation");
  const toml::node* rotation = reader.get("rotation");
  if (quaternion != nullptr && rotation != nullptr) {
    reader.fail(*rotation, "rotation", "either orientation or rotation, not both");
  }
  if (quaternion != nullptr) {
    const auto* a = quaternion->as_array();
    const char* expected = "a unit quaternion [p0, p1, p2, p3] (scalar first)";
    if (a == nullptr || a->size() != 4) reader.fail(*quaternion, "orientation", expected);
    Vector4 p;
    for (std::size_t k = 0; k < 4; ++k) {
      p[static_cast<Eigen::Index>(k)] =
          reader.to_real_element(*a->get(k), "orientation", expected, kAny);
    }
    if (std::abs(p.norm() - 1.0) > 1e-6) reader.fail(*quaternion, "orientation", expected);
    return kinematics::Quaternion(p / p.norm());
  }
  if (rotation != nullptr) {
    const auto* a = rotation->as_array();
    const char* expected = "[x, y, z, angle in degrees] with a non-zero axis (x, y, z)";
    if (a == nullptr || a->size() != 4) reader.fail(*rotation, "rotation", expected);
    Vector3 axis;
    for (std::size_t k = 0; k < 3; ++k) {
      axis[static_cast<Eigen::Index>(k)] =
          reader.to_real_element(*a->get(k), "rotation", expected, kAny);
    }
    const double degrees = reader.to_real_element(*a->get(3), "rotation", expected, kAny);
    if (!(axis.norm() > 0.0)) reader.fail(*rotation, "rotation", expected);
    return kinematics::quaternion_from_rotation_vector(axis.normalized() * degrees * M_PI / 180.0);
  }
  return kinematics::Quaternion();
}

Region read_region(TableReader& reader, std::string_view key) {
  const toml::node* node = reader.get(key);
  const char* expected = "a table { min = [x, y, z], max = [x, y, z] } with min < max";
  if (node == nullptr) reader.missing(key, expected);
  if (!node->is_table()) reader.fail(*node, key, expected);
  TableReader t(*node->as_table(), reader.key_path(key), reader.file());
  Region region;
  region.min = t.vector_required("min");
  region.max = t.vector_required("max");
  if (!(region.min.array() < region.max.array()).all()) {
    reader.fail(*node, key, expected);
  }
  t.finish();
  return region;
}

void read_simulation(TableReader& t, Scene& scene) {
  scene.settings.dt = t.real_required("dt", kPositive);
  scene.end_time = t.real_required("end_time", kPositive);
  scene.settings.I_g = t.vector("gravity", scene.settings.I_g);
  if (!std::isfinite(scene.settings.I_g.squaredNorm())) {  // the energies would overflow at once
    t.fail(*t.table().get("gravity"), "gravity",
           "a vector of magnitude below 10¹⁵⁴ m/s² (its square must be finite)");
  }
  scene.seed =
      static_cast<std::uint64_t>(t.integer("seed", 1, 0, std::numeric_limits<std::int64_t>::max()));
  if (const toml::node* node = t.get("domain")) {
    (void)node;
    scene.domain.enabled = true;
    scene.domain.box = read_region(t, "domain");
  }
  if (const toml::node* node = t.get("periodic")) {
    const std::string expected = "an array of distinct axis names \"x\", \"y\", \"z\"";
    const auto* axes = node->as_array();
    if (axes == nullptr) t.fail(*node, "periodic", expected);
    for (const toml::node& axis : *axes) {
      const auto* name = axis.as_string();
      const std::string_view text = name != nullptr ? std::string_view(name->get()) : "";
      const std::size_t d = text == "x" ? 0 : text == "y" ? 1 : text == "z" ? 2 : 3;
      if (d == 3 || scene.domain.periodic[d]) t.fail(axis, "periodic", expected);
      scene.domain.periodic[d] = true;
    }
    if (scene.domain.any_periodic() && !scene.domain.enabled) {
      t.fail(*node, "periodic", "a domain = { min, max } beside it: the periodic box");
    }
  }
  const double steps = scene.end_time / scene.settings.dt;
  if (steps > static_cast<double>(kMaxSteps)) {
    t.fail(*t.table().get("end_time"), "end_time", "at most 10¹² steps of dt");
  }
  t.finish();
}

// The settings a scene gets where its [solver] table names nothing (chapter 7's table of keys;
// chapter 6, "What a scene gets", measures them): SOR held to the natural-map residual 1e-4 at
// α = 1.3, the gap-aware law's look-ahead of 0.1 r (no overlap recovery: it lifts a resting pile
// and turns a silo's wall friction round) and Morton reordering every 100 steps. The library's own
// StepSettings stay Moreau's scheme as derived (law off, the percussions' change).
void scene_solver_defaults(timestep::StepSettings& s) {
  s.solver.criterion = contact::Criterion::natural_residual;
  s.solver.rel_tol = 1e-4;
  s.solver.alpha = 1.3;
  s.look_ahead = 0.1;
  s.look_ahead_reach = 1.0;
  s.reorder_interval = 100;
}

void read_solver(TableReader& t, Scene& scene) {
  auto& s = scene.settings;
  s.method = static_cast<contact::Method>(t.choice("method", {"sor", "jor", "apgd", "newton"}, 0));
  s.solver.max_iterations =
      static_cast<int>(t.integer("max_iterations", s.solver.max_iterations, 1, 100000000));
  s.solver.min_iterations = static_cast<int>(
      t.integer("min_iterations", s.solver.min_iterations, 0, s.solver.max_iterations));
  s.solver.rel_tol = t.real("tolerance", s.solver.rel_tol, kNonNegative);
  s.solver.abs_tol = t.real("absolute_tolerance", s.solver.abs_tol, kNonNegative);
  s.solver.alpha = t.real("alpha", s.solver.alpha, Range{0.0, 2.0, true, true});
  s.solver.criterion = static_cast<contact::Criterion>(
      t.choice("criterion", {"percussion_change", "velocity_change", "natural_residual"},
               static_cast<std::size_t>(s.solver.criterion)));
  s.solver.newton.linear_solver = static_cast<contact::LinearSolver>(
      t.choice("linear_solver", {"automatic", "direct", "gmres"}, 0));
  s.solver.newton.hybrid_sweeps =
      static_cast<int>(t.integer("hybrid_sweeps", s.solver.newton.hybrid_sweeps, 0, 100000000));
  s.warm_start = t.boolean("warm_start", s.warm_start);
  s.on_non_convergence = static_cast<timestep::NonConvergence>(
      t.choice("on_non_convergence", {"count", "warn", "stop"}, 0));
  s.contact_tolerance = t.real("contact_tolerance", s.contact_tolerance, kNonNegative);
  s.drift_correction = t.real("drift_correction", s.drift_correction, kUnit);
  s.overlap_recovery = t.real("overlap_recovery", s.overlap_recovery, kUnit);
  s.max_recovery_speed = t.real("max_recovery_speed", s.max_recovery_speed, kPositive);
  s.look_ahead = t.real("look_ahead", s.look_ahead, kNonNegative);
  // The reach extends the look-ahead: where a scene does not name it, it is 0 without a
  // look-ahead and at least the look-ahead with one.
  if (const toml::node* reach = t.get("look_ahead_reach")) {
    s.look_ahead_reach = t.real("look_ahead_reach", s.look_ahead_reach, kNonNegative);
    if (s.look_ahead_reach != 0.0 && !(s.look_ahead > 0.0 && s.look_ahead_reach >= s.look_ahead)) {
      std::ostringstream expected;
      expected << "0 (none) or, with a look_ahead > 0, at least the look_ahead (" << s.look_ahead
               << ")";
      t.fail(*reach, "look_ahead_reach", expected.str());
    }
  } else {
    s.look_ahead_reach = s.look_ahead == 0.0 ? 0.0 : std::max(s.look_ahead_reach, s.look_ahead);
  }
  s.reorder_interval =
      static_cast<int>(t.integer("reorder_interval", s.reorder_interval, 0, 1000000000));
  s.orientation_update = static_cast<timestep::OrientationUpdate>(
      t.choice("orientation_update", {"exponential_map", "add_and_normalize"}, 0));
  t.finish();
}

contact::ContactMaterial read_law(TableReader& t) {
  contact::ContactMaterial law;
  law.mu = t.real_required("mu", kNonNegative);
  law.eps_N = t.real("eps_N", 0.0, kUnit);
  law.eps_T = t.real("eps_T", 0.0, Range{-1.0, 1.0, false, false});
  return law;
}

std::size_t material_index(const Scene& scene, TableReader& t, std::string_view key,
                           const std::string& name) {
  for (std::size_t k = 0; k < scene.materials.size(); ++k) {
    if (scene.materials[k] == name) return k;
  }
  std::string expected = "the name of a declared material ([[material]])";
  std::vector<std::string_view> names(scene.materials.begin(), scene.materials.end());
  const std::string near = closest_key(name, names);
  if (!near.empty()) expected += " (did you mean \"" + near + "\"?)";
  t.fail(*t.table().get(key), key, expected);
}

void read_static(TableReader& t, Scene& scene, const std::filesystem::path& folder) {
  StaticSpec s;
  s.name = t.string_opt("name").value_or(t.path());
  const std::size_t kind =
      t.choice("shape", {"half_space", "box", "capsule", "sphere", "mesh"}, std::nullopt);
  s.material = t.string_required("material", "the name of a declared material");
  material_index(scene, t, "material", s.material);
  const Vector3 position = t.vector("position", Vector3::Zero());
  s.pose.I_r = position;
  s.until = t.real_opt("until", kPositive);
  switch (kind) {
    case 0: {
      // A half-space has no orientation of its own: its normal says where it faces.
      for (const char* key : {"rotation", "orientation"}) {
        if (const toml::node* node = t.get(key)) {
          t.fail(*node, key, "no orientation: a half-space is oriented by its normal (key normal)");
        }
      }
      const Vector3 normal = t.vector_required("normal");
      if (!(normal.norm() > 0.0)) t.fail(*t.table().get("normal"), "normal", "a non-zero normal");
      const Vector3 n = normal.normalized();
      // The plane passes through `point` (default: the origin); the solid lies below it.
      const Vector3 point = t.vector("point", Vector3::Zero());
      s.shape = collision::HalfSpace{n, n.dot(point)};
      break;
    }
    case 1:
      s.shape = collision::Box{t.vector_required("half_extents", kPositive)};
      break;
    case 2:
      s.shape = collision::Capsule{t.real_required("radius", kPositive),
                                   t.real_required("half_length", kNonNegative)};
      break;
    case 3:
      s.shape = collision::Sphere{t.real_required("radius", kPositive)};
      break;
    default: {
      const std::optional<std::string> name = t.file_name_opt("file");
      if (!name) t.missing("file", "the path of an OBJ file");
      const std::string file = *name;
      const double scale = t.real("scale", 1.0, kPositive);
      s.mesh_file = folder / file;
      body::TriangleMesh mesh;
      try {
        mesh = body::read_obj(s.mesh_file);
      } catch (const Error& e) {
        t.fail_at(t.table().get("file")->source(), "file", "a readable OBJ mesh", e.what());
      }
      const Matrix3 A = kinematics::rotation_matrix(read_orientation(t));
      for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
        const Vector3 x = mesh.V.row(v).transpose();
        mesh.V.row(v) = (position + A * (scale * x)).transpose();
      }
      try {
        s.shape = std::make_shared<const collision::StaticMesh>(std::move(mesh));
      } catch (const Error& e) {
        t.fail_at(t.table().get("file")->source(), "file", "a valid triangle mesh", e.what());
      }
      s.pose = collision::Placement{};
      t.finish();
      scene.statics.push_back(std::move(s));
      return;
    }
  }
  if (kind != 0) s.pose.A_IC = kinematics::rotation_matrix(read_orientation(t));
  t.finish();
  scene.statics.push_back(std::move(s));
}

GeneratorSpec read_generator(TableReader& group, const Scene& scene, std::size_t index) {
  GeneratorSpec g;
  g.seed = scene.seed + 0x9E3779B97F4A7C15ULL * (index + 1);
  const bool has_positions = group.get("positions") != nullptr;
  const toml::table* table = group.table_opt("generator");
  const char* either = "either positions = [[x, y, z], …] or a table [bodies.generator]";
  if (!has_positions && table == nullptr)
    group.neither({"positions", "generator"}, "generator", either);
  if (has_positions && table != nullptr) {
    group.fail_at(group.table().source(), "generator", either, "both");
  }
  if (has_positions) {
    const toml::node* node = group.table().get("positions");
    const auto* a = node->as_array();
    const char* expected = "a non-empty array of positions [x, y, z]";
    if (a == nullptr || a->empty()) group.fail(*node, "positions", expected);
    for (const toml::node& p : *a) g.positions.push_back(group.to_vector3(p, "positions", kAny));
    g.kind = GeneratorKind::list;
    g.count = g.positions.size();
    g.random_orientation = false;
    return g;
  }
  TableReader t(*table, group.key_path("generator"), group.file());
  g.kind = static_cast<GeneratorKind>(
      1 + t.choice("kind", {"lattice", "packing", "inflow"}, std::nullopt));
  g.region = read_region(t, "region");
  g.seed = static_cast<std::uint64_t>(t.integer("seed", static_cast<std::int64_t>(g.seed >> 1), 0,
                                                std::numeric_limits<std::int64_t>::max()));
  g.random_orientation = t.boolean("random_orientation", false);
  const std::int64_t max_count = 1'000'000'000'000;
  switch (g.kind) {
    case GeneratorKind::lattice:
      g.count = static_cast<std::uint64_t>(t.integer("count", 0, 0, max_count));
      g.spacing = t.real("spacing", 0.0, kNonNegative);
      g.jitter = t.real("jitter", 0.0, kUnit);
      break;
    case GeneratorKind::packing:
      g.count = static_cast<std::uint64_t>(t.integer("count", 0, 1, max_count));
      if (!t.table().get("count")) t.missing("count", "an integer ≥ 1");
      g.max_attempts = static_cast<int>(t.integer("max_attempts", g.max_attempts, 1, 100000000));
      break;
    case GeneratorKind::inflow:
      g.rate = t.real_required("rate", kPositive);
      g.count = static_cast<std::uint64_t>(t.integer("count", 0, 0, max_count));
      g.start = t.real("start", 0.0, kNonNegative);
      g.stop = t.real("stop", 0.0, kNonNegative);
      if (g.stop > 0.0 && g.stop <= g.start) {
        t.fail(*t.table().get("stop"), "stop", "a time after start (or 0: the end of the run)");
      }
      g.max_attempts = static_cast<int>(t.integer("max_attempts", 20, 1, 100000000));
      break;
    case GeneratorKind::list:
      break;
  }
  t.finish();
  return g;
}

void read_group(TableReader& t, Scene& scene, std::size_t index) {
  BodyGroup g;
  g.name = t.string_opt("name").value_or(t.path());
  const std::size_t shape = t.choice("shape", {"sphere", "box", "capsule"}, 0);
  g.shape = shape == 0   ? collision::ShapeKind::sphere
            : shape == 1 ? collision::ShapeKind::box
                         : collision::ShapeKind::capsule;
  if (g.shape == collision::ShapeKind::box) {
    g.half_extents = t.vector_required("half_extents", kPositive);
  } else {
    g.radius = read_radius(t, "radius");
    if (g.shape == collision::ShapeKind::capsule) {
      g.half_length = t.real_required("half_length", kNonNegative);
    }
  }
  g.density = t.real_opt("density", kPositive);
  g.mass = t.real_opt("mass", kPositive);
  const char* one_of = "exactly one of density [kg/m³] and mass [kg]";
  if (!g.density && !g.mass) t.neither({"density", "mass"}, "density", one_of);
  if (g.density && g.mass) t.fail_at(t.table().source(), "density", one_of, "both");
  g.material = t.string_required("material", "the name of a declared material");
  material_index(scene, t, "material", g.material);
  g.I_v_S = t.vector("velocity", Vector3::Zero());
  g.K_omega = t.vector("angular_velocity", Vector3::Zero());
  g.fixed = t.boolean("fixed", false);
  g.generator = read_generator(t, scene, index);
  t.finish();
  scene.groups.push_back(std::move(g));
}

void read_output(TableReader& t, Scene& scene) {
  if (auto file = t.file_name_opt("file")) scene.output.file = *file;
  scene.output.every =
      static_cast<std::uint64_t>(t.integer("every", static_cast<std::int64_t>(scene.output.every),
                                           0, std::numeric_limits<std::int64_t>::max()));
  scene.output.float32 = t.choice("precision", {"double", "float"}, 0) == 1;
  scene.output.contacts = t.boolean("contacts", false);
  t.finish();
}

void read_checkpoint(TableReader& t, Scene& scene) {
  if (auto file = t.file_name_opt("file")) scene.checkpoint.file = *file;
  scene.checkpoint.every = static_cast<std::uint64_t>(
      t.integer("every", 0, 0, std::numeric_limits<std::int64_t>::max()));
  t.finish();
}

void read_parallel(TableReader& t, Scene& scene) {
  ParallelSpec& p = scene.parallel;
  p.partition =
      static_cast<ParallelSpec::Partition>(t.choice("partition", {"grid", "bisection"}, 0));
  p.average_every = static_cast<int>(t.integer("average_every", p.average_every, 1, 1'000'000));
  p.rebalance_every =
      static_cast<int>(t.integer("rebalance_every", p.rebalance_every, 0, 1'000'000'000));
  p.imbalance = t.real("imbalance", p.imbalance, Range{1.0});
  t.finish();
}

}  // namespace

Scene parse_scene(std::string_view text, const std::filesystem::path& file) {
  const std::string name = file.string();
  toml::table root;
  try {
    root = toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    std::ostringstream out;
    out << position(name, e.source()) << ": not valid TOML: " << e.description();
    throw SceneError(out.str());
  }
  Scene scene;
  scene.file = file;
  scene.text = std::string(text);
  scene.name = file.stem().string().empty() ? "scene" : file.stem().string();
  const std::filesystem::path folder = file.parent_path();

  TableReader top(root, "", name);
  {
    const toml::table* t = top.table_opt("simulation");
    if (t == nullptr) top.missing("simulation", "a table [simulation] with dt and end_time");
    TableReader reader(*t, "simulation", name);
    read_simulation(reader, scene);
  }
  scene_solver_defaults(scene.settings);
  if (const toml::table* t = top.table_opt("solver")) {
    TableReader reader(*t, "solver", name);
    read_solver(reader, scene);
  }
  const toml::array* materials = top.tables_opt("material");
  if (materials == nullptr) top.missing("material", "at least one [[material]] with a name");
  for (std::size_t k = 0; k < materials->size(); ++k) {
    TableReader t(*materials->get(k)->as_table(), indexed("material", k), name);
    if (k == timestep::MaterialTable::kMaxMaterials) {
      t.fail_at(t.table().source(), "name",
                "at most " + std::to_string(timestep::MaterialTable::kMaxMaterials) +
                    " materials (the table of laws holds every pair)",
                std::to_string(materials->size()) + " materials");
    }
    std::string material = t.string_required("name", "the material's name");
    if (std::find(scene.materials.begin(), scene.materials.end(), material) !=
        scene.materials.end()) {
      t.fail(*t.table().get("name"), "name", "a name not used by another material");
    }
    t.finish();
    scene.materials.push_back(std::move(material));
  }
  if (const toml::table* t = top.table_opt("default_contact")) {
    TableReader reader(*t, "default_contact", name);
    scene.default_contact = read_law(reader);
    reader.finish();
  }
  if (const toml::array* contacts = top.tables_opt("contact")) {
    std::set<std::pair<std::size_t, std::size_t>> seen;
    for (std::size_t k = 0; k < contacts->size(); ++k) {
      TableReader t(*contacts->get(k)->as_table(), indexed("contact", k), name);
      const toml::node* pair = t.get("materials");
      const char* expected = "an array of two material names [\"a\", \"b\"]";
      if (pair == nullptr) t.missing("materials", expected);
      const auto* a = pair->as_array();
      if (a == nullptr || a->size() != 2 || !a->get(0)->is_string() || !a->get(1)->is_string()) {
        t.fail(*pair, "materials", expected);
      }
      ContactSpec c;
      c.a = *a->get(0)->value<std::string>();
      c.b = *a->get(1)->value<std::string>();
      for (const std::string* m : {&c.a, &c.b}) {
        if (std::find(scene.materials.begin(), scene.materials.end(), *m) ==
            scene.materials.end()) {
          std::vector<std::string_view> names(scene.materials.begin(), scene.materials.end());
          const std::string near = closest_key(*m, names);
          t.fail_at(pair->source(), "materials",
                    "names of declared materials" +
                        (near.empty() ? "" : " (did you mean \"" + near + "\"?)"),
                    "\"" + *m + "\"");
        }
      }
      const auto ia = material_index(scene, t, "materials", c.a);
      const auto ib = material_index(scene, t, "materials", c.b);
      if (!seen.insert({std::min(ia, ib), std::max(ia, ib)}).second) {
        t.fail(*pair, "materials", "a pair of materials without an earlier [[contact]]");
      }
      c.law = read_law(t);
      t.finish();
      scene.contacts.push_back(std::move(c));
    }
  }
  if (const toml::array* statics = top.tables_opt("static")) {
    for (std::size_t k = 0; k < statics->size(); ++k) {
      TableReader t(*statics->get(k)->as_table(), indexed("static", k), name);
      read_static(t, scene, folder);
    }
  }
  const toml::array* groups = top.tables_opt("bodies");
  if (groups == nullptr) top.missing("bodies", "at least one [[bodies]] group");
  for (std::size_t k = 0; k < groups->size(); ++k) {
    TableReader t(*groups->get(k)->as_table(), indexed("bodies", k), name);
    read_group(t, scene, k);
  }
  if (const toml::table* t = top.table_opt("output")) {
    TableReader reader(*t, "output", name);
    read_output(reader, scene);
  }
  if (const toml::table* t = top.table_opt("checkpoint")) {
    TableReader reader(*t, "checkpoint", name);
    read_checkpoint(reader, scene);
  }
  if (const toml::table* t = top.table_opt("parallel")) {
    TableReader reader(*t, "parallel", name);
    read_parallel(reader, scene);
  }
  top.finish();

  // Every pair of materials that can meet needs a law: body–body and body–static.
  if (!scene.default_contact) {
    std::set<std::string> body_materials;
    for (const BodyGroup& g : scene.groups) body_materials.insert(g.material);
    std::set<std::string> all = body_materials;
    for (const StaticSpec& s : scene.statics) all.insert(s.material);
    for (const std::string& a : body_materials) {
      for (const std::string& b : all) {
        const bool found = std::any_of(
            scene.contacts.begin(), scene.contacts.end(),
            [&](const ContactSpec& c) { return (c.a == a && c.b == b) || (c.a == b && c.b == a); });
        if (!found) {
          throw SceneError(name + ": contact: expected a [[contact]] with materials = [\"" + a +
                           "\", \"" + b + "\"] (bodies of \"" + a + "\" can touch \"" + b +
                           "\") or a [default_contact], found neither");
        }
      }
    }
  }
  // The length the active-set tolerance scales, once for the whole run and the same on every
  // process: the smallest bounding radius any group can produce (not the smallest present, which
  // an inflow or an outlet would change).
  for (const BodyGroup& g : scene.groups) {
    const double r = smallest_bounding_radius(g);
    if (scene.settings.tolerance_radius == 0.0 || r < scene.settings.tolerance_radius) {
      scene.settings.tolerance_radius = r;
    }
  }
  if (scene.output.file.empty()) scene.output.file = scene.name + ".h5";
  if (scene.checkpoint.file.empty()) scene.checkpoint.file = scene.name + ".ckpt.h5";
  return scene;
}

Scene load_scene(const std::filesystem::path& file) {
  // A FIFO would block and a device never end: only a regular file, of bounded size, is read.
  if (const std::string problem = regular_file_problem(file, "scene file"); !problem.empty()) {
    throw SceneError(file.string() + ": " + problem);
  }
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(file, error);
  if (!error && size > kMaxSceneBytes) {
    throw SceneError(file.string() + ": expected a scene file of at most " +
                     std::to_string(kMaxSceneBytes >> 20) + " MiB, found " +
                     std::to_string(size >> 20) + " MiB");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw SceneError(file.string() + ": cannot open the scene file for reading");
  // One byte more than expected: a file that grew while being read is noticed.
  std::string text(static_cast<std::size_t>(error ? kMaxSceneBytes : size) + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw SceneError(file.string() + ": cannot read the scene file");
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > kMaxSceneBytes || (!error && text.size() > size)) {
    throw SceneError(file.string() + ": expected a scene file of at most " +
                     std::to_string(kMaxSceneBytes >> 20) + " MiB");
  }
  return parse_scene(text, file);
}

std::string summary(const Scene& scene) {
  std::ostringstream out;
  out << "scene " << scene.file.string() << "\n";
  out << "  time: dt = " << scene.settings.dt << " s, end_time = " << scene.end_time << " s ("
      << scene.steps() << " steps), gravity = (" << scene.settings.I_g.transpose() << ") m/s²\n";
  const timestep::StepSettings& settings = scene.settings;
  constexpr std::array<std::string_view, 3> kCriteria = {"percussion change", "velocity change",
                                                         "natural residual"};
  out << "  solver: " << contact::method_name(settings.method) << ", "
      << kCriteria[static_cast<std::size_t>(settings.solver.criterion)] << " tolerance "
      << settings.solver.rel_tol << ", alpha " << settings.solver.alpha << ", at most "
      << settings.solver.max_iterations << " iterations"
      << (settings.warm_start ? ", warm start" : "") << "\n";
  out << "  normal law: ";
  if (settings.look_ahead > 0.0 || settings.overlap_recovery > 0.0) {
    out << "gap-aware, look_ahead " << settings.look_ahead << " r";
    if (settings.look_ahead_reach > settings.look_ahead) {
      out << ", reach " << settings.look_ahead_reach << " r for approaching pairs";
    }
    out << ", overlap_recovery " << settings.overlap_recovery;
    if (std::isfinite(settings.max_recovery_speed)) {
      out << ", max_recovery_speed " << settings.max_recovery_speed << " m/s";
    }
    out << "\n";
  } else {
    out << "Moreau's (look_ahead and overlap_recovery 0)\n";
  }
  if (scene.domain.any_periodic()) {
    out << "  periodic along";
    for (int d = 0; d < 3; ++d) {
      if (scene.domain.periodic[static_cast<std::size_t>(d)]) out << ' ' << "xyz"[d];
    }
    out << " (the domain's box), on the parallel engine\n";
  }
  out << "  materials:";
  for (const std::string& m : scene.materials) out << ' ' << m;
  out << "\n";
  for (const ContactSpec& c : scene.contacts) {
    out << "  contact " << c.a << "–" << c.b << ": mu = " << c.law.mu << ", eps_N = " << c.law.eps_N
        << ", eps_T = " << c.law.eps_T << "\n";
  }
  if (scene.default_contact) {
    out << "  other pairs: mu = " << scene.default_contact->mu
        << ", eps_N = " << scene.default_contact->eps_N
        << ", eps_T = " << scene.default_contact->eps_T << "\n";
  }
  for (const StaticSpec& s : scene.statics) {
    out << "  static " << s.name << ": " << collision::kind_name(collision::kind(s.shape)) << " ("
        << s.material << ")";
    if (!s.mesh_file.empty()) out << " from " << s.mesh_file.string();
    out << "\n";
  }
  for (const BodyGroup& g : scene.groups) {
    out << "  bodies " << g.name << ": " << collision::kind_name(g.shape);
    if (g.shape != collision::ShapeKind::box) out << ", radius " << g.radius.describe();
    out << ", " << g.material << ", " << generator_name(g.generator.kind);
    if (g.generator.count > 0) out << ", count " << g.generator.count;
    if (g.generator.kind == GeneratorKind::inflow) out << ", rate " << g.generator.rate << " /s";
    out << "\n";
  }
  out << "  output: " << scene.output.file.string() << ", a record every " << scene.output.every
      << " steps (" << (scene.output.float32 ? "float" : "double") << ")\n";
  out << "  checkpoint: " << scene.checkpoint.file.string();
  if (scene.checkpoint.every > 0) out << " every " << scene.checkpoint.every << " steps";
  out << "\n";
  return out.str();
}

}  // namespace grbd::scene
