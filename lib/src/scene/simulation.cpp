// A scene made runnable (chapter 7): materials, static geometry, generators, stepper, outlet.

#include "grbd/scene/simulation.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <unordered_map>

#include "grbd/body/mass_properties.hpp"
#include "grbd/body/rigid_body.hpp"
#include "grbd/collision/narrow_phase.hpp"
#include "grbd/collision/world.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/kinematics/rigid_motion.hpp"
#include "grbd/kinematics/rotation.hpp"

namespace grbd::scene {

namespace {

using collision::ShapeKind;

using timestep::BodyRecord;

// The radius of the sphere about S that holds the body.
double bounding_radius(const BodyRecord& body) { return collision::bounding_radius(body.shape); }

// The radius of a sphere or a capsule (0 for a box): what a group's distribution draws.
double radius_of(const BodyRecord& body) {
  if (const auto* sphere = std::get_if<collision::Sphere>(&body.shape)) return sphere->radius;
  if (const auto* capsule = std::get_if<collision::Capsule>(&body.shape)) return capsule->radius;
  return 0.0;
}

// A uniformly distributed unit quaternion (Shoemake 1992, "Uniform random rotations").
Vector7 random_orientation(Random& random, const Vector3& position) {
  const double u1 = random.uniform();
  const double u2 = 2.0 * M_PI * random.uniform();
  const double u3 = 2.0 * M_PI * random.uniform();
  const double a = std::sqrt(1.0 - u1);
  const double b = std::sqrt(u1);
  Vector7 q;
  q << position, a * std::sin(u2), a * std::cos(u2), b * std::sin(u3), b * std::cos(u3);
  q.tail<4>().normalize();
  return q;
}

// Spheres (bounding spheres) in a hash grid of cells of edge h ≥ r_i + r_j for any two of them,
// so that an overlap is always with a sphere of a neighbouring cell.
class OverlapGrid {
 public:
  explicit OverlapGrid(double h = 1.0) : h_(h) {}
  void insert(const Vector3& c, double r) {
    const auto index = static_cast<std::uint32_t>(centres_.size());
    centres_.push_back(c);
    radii_.push_back(r);
    cells_[key(cell(c))].push_back(index);
  }
  // The index (in the order of insertion) of a sphere that the sphere (c, r) overlaps by more
  // than `slack` [m], or −1.
  std::int64_t find(const Vector3& c, double r, double slack = 0.0) const {
    const Eigen::Array3i k = cell(c);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = cells_.find(key(k + Eigen::Array3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (const std::uint32_t j : it->second) {
            const double reach = r + radii_[j] - slack;
            if ((centres_[j] - c).squaredNorm() < reach * reach) return j;
          }
        }
      }
    }
    return -1;
  }
  bool overlaps(const Vector3& c, double r) const { return find(c, r) >= 0; }
  // Empties the grid for a new cell size, keeping its memory.
  void reset(double h) {
    h_ = h;
    centres_.clear();
    radii_.clear();
    for (auto& [k, cell] : cells_) cell.clear();
  }

 private:
  // The clamp comes before the conversion (converting a double outside the range of int is
  // undefined, and so is k ± 1 at its ends): far cells share the clamped one, which only adds
  // candidates, since |clamp(a) − clamp(b)| ≤ |a − b| keeps neighbours neighbours. NaN → 0.
  Eigen::Array3i cell(const Vector3& c) const {
    constexpr double kLimit = 0x1p30;
    Eigen::Array3i k;
    for (int axis = 0; axis < 3; ++axis) {
      const double t = std::floor(c[axis] / h_);
      k[axis] = std::isnan(t) ? 0 : static_cast<int>(std::clamp(t, -kLimit, kLimit));
    }
    return k;
  }
  static std::uint64_t key(const Eigen::Array3i& k) {
    const auto part = [](int v) {
      return static_cast<std::uint64_t>(static_cast<std::uint32_t>(v)) & 0x1FFFFF;
    };
    return part(k.x()) | (part(k.y()) << 21) | (part(k.z()) << 42);
  }
  double h_;
  std::vector<Vector3> centres_;
  std::vector<double> radii_;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
};

// The state of a new body of `group` at `position`: the group's velocities, and a random
// orientation when the generator asks for one (drawn from `random`), else the identity.
body::State initial_state(const BodyGroup& group, Random& random, const Vector3& position) {
  body::State x;
  if (group.generator.random_orientation) {
    x.q = random_orientation(random, position);
  } else {
    x.q << position, 1.0, 0.0, 0.0, 0.0;
  }
  x.u << group.I_v_S, group.K_omega;
  return x;
}

[[noreturn]] void fail(const Scene& scene, std::size_t group, const std::string& message) {
  throw SceneError(scene.file.string() + ": bodies[" + std::to_string(group) + "] (" +
                   scene.groups[group].name + "): " + message);
}

constexpr std::uint64_t kMaxBodies = 100'000'000;

// The memory this process can still take [bytes]: the smaller of what the system has available
// (MemAvailable + SwapFree of /proc/meminfo) and what the address-space limit leaves (RLIMIT_AS
// less the current size); "unlimited" where neither is known.
double available_memory() {
  double available = std::numeric_limits<double>::infinity();
  if (std::ifstream meminfo("/proc/meminfo"); meminfo) {
    double total = 0.0;
    int found = 0;
    for (std::string line; std::getline(meminfo, line);) {  // "MemAvailable:  123456 kB"
      std::istringstream fields(line);
      std::string key;
      double kib = 0.0;
      if ((fields >> key >> kib) && (key == "MemAvailable:" || key == "SwapFree:")) {
        total += 1024.0 * kib;
        ++found;
      }
    }
    if (found == 2) available = total;
  }
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    double used = 0.0;
    if (std::ifstream statm("/proc/self/statm"); statm) {
      double pages = 0.0;
      statm >> pages;
      used = pages * static_cast<double>(sysconf(_SC_PAGESIZE));
    }
    available = std::min(available, static_cast<double>(limit.rlim_cur) - used);
  }
  return available;
}

}  // namespace

void Simulation::require_memory(std::uint64_t bodies, std::size_t group) const {
  const double needed = static_cast<double>(bodies) * kBytesPerBody;
  const double available = available_memory();
  if (needed > available) {
    std::ostringstream out;
    out << "generator: " << bodies << " bodies in all need about " << needed / 1e9 << " GB ("
        << kBytesPerBody << " bytes per body), more than the " << available / 1e9
        << " GB this process can still take; lower count or enlarge the machine";
    fail(scene_, group, out.str());
  }
}

void Simulation::require_invertible_constants() const {
  // Mass and moments grow with the radius (as r³ and r⁵): the extremes of the distribution give
  // the extremes of both, and each must have a finite inverse (the step divides by them).
  for (std::size_t g = 0; g < scene_.groups.size(); ++g) {
    const BodyGroup& group = scene_.groups[g];
    for (const double r : {group.radius.min(), group.radius.max()}) {
      const BodyRecord c = body_for(group, r);
      try {
        body::require_valid(c.inertia, "");  // the rule BodySystem::add applies to every body
        continue;
      } catch (const InvalidArgument&) {
      }
      std::ostringstream out;
      out << (group.shape == ShapeKind::box ? "half_extents" : "radius") << ", "
          << (group.density ? "density" : "mass") << ": a body of "
          << (group.shape == ShapeKind::box ? "this box" : "radius " + format_number(r) + " m")
          << " and "
          << (group.density ? "density " + format_number(*group.density) + " kg/m³"
                            : "mass " + format_number(*group.mass) + " kg")
          << " has the mass " << format_number(c.inertia.m) << " kg and the principal moments ("
          << format_number(c.inertia.K_Theta[0]) << ", " << format_number(c.inertia.K_Theta[1])
          << ", " << format_number(c.inertia.K_Theta[2])
          << ") kg m²: expected values whose inverses are finite (the derived mass or inertia "
             "under- or overflows the doubles)";
      fail(scene_, g, out.str());
    }
  }
}

namespace {
// The bounding radius of a body of `group` whose radius (a sphere's, a capsule's segment's) is r.
double group_bounding_radius(const BodyGroup& group, double r) {
  switch (group.shape) {
    case ShapeKind::box:
      return collision::bounding_radius(collision::Box{group.half_extents});
    case ShapeKind::capsule:
      return collision::bounding_radius(collision::Capsule{r, group.half_length});
    default:
      return collision::bounding_radius(collision::Sphere{r});
  }
}
}  // namespace

double largest_bounding_radius(const BodyGroup& group) {
  return group_bounding_radius(group, group.radius.max());
}

double smallest_bounding_radius(const BodyGroup& group) {
  return group_bounding_radius(group, group.radius.min());
}

// Buffers of the generators, kept between steps so that an inflow allocates nothing once warm.
struct Simulation::Scratch {
  OverlapGrid grid;
  std::vector<timestep::GlobalId> owner;  // the id of each sphere in grid
  std::vector<Vector4> near;              // the bodies near an inflow region: centre, radius
  std::vector<std::vector<std::byte>> gathered;
  std::vector<collision::ContactGeometry> contacts;
  Scratch() = default;
};

Simulation::~Simulation() = default;

std::pair<double, std::size_t> Simulation::static_gap(const collision::Shape& shape,
                                                      const body::State& x) {
  const collision::Placement pose{kinematics::position(x.q),
                                  kinematics::rotation_matrix(kinematics::orientation(x.q))};
  double gap = std::numeric_limits<double>::infinity();
  std::size_t which = 0;
  const auto objects = statics_.objects();
  for (std::size_t s = 0; s < objects.size(); ++s) {
    std::vector<collision::ContactGeometry>& found = scratch_->contacts;
    found.clear();
    // The kernels take the shapes in the kind order sphere, box, capsule, half-space, mesh.
    if (collision::kind(shape) <= collision::kind(objects[s].shape)) {
      collision::collide(shape, pose, objects[s].shape, objects[s].pose, 0.0, found);
    } else {
      collision::collide(objects[s].shape, objects[s].pose, shape, pose, 0.0, found);
    }
    for (const collision::ContactGeometry& geometry : found) {
      if (geometry.g_N < gap) {
        gap = geometry.g_N;
        which = static_cast<std::size_t>(objects[s].id);  // the scene's index
      }
    }
  }
  return {gap, which};
}

Simulation::Simulation(Scene scene) : Simulation(std::move(scene), nullptr, nullptr) {}

Simulation::Simulation(Scene scene, const SimulationState& state)
    : Simulation(std::move(scene), &state, nullptr) {}

Simulation::Simulation(Scene scene, const SimulationState* state, const Distribution& distribution)
    : Simulation(std::move(scene), state, &distribution) {}

namespace {

// Chapter 6's stepper on its own: the serial run.
class SerialEngine final : public StepEngine {
 public:
  SerialEngine(timestep::BodySystem& system, const timestep::StaticGeometry& statics,
               const timestep::MaterialTable& materials, const timestep::StepSettings& settings)
      : stepper_(system, statics, materials, settings) {}
  timestep::StepReport step() override {
    stepper_.reorder_if_due();  // between steps, where a parallel run migrates bodies
    return stepper_.step();
  }
  timestep::MoreauStepper& stepper() override { return stepper_; }

 private:
  timestep::MoreauStepper stepper_;
};

}  // namespace

Simulation::Simulation(Scene scene, const SimulationState* state, const Distribution* distribution)
    : scene_(std::move(scene)), distribution_(distribution), scratch_(std::make_unique<Scratch>()) {
  if (scene_.domain.any_periodic() && distribution_ == nullptr) {
    throw SceneError(scene_.file.string() +
                     ": [simulation] periodic: a periodic scene runs on "
                     "the parallel engine, also on one process (parallel::SceneDecomposition; "
                     "grbd run uses it)");
  }
  for (const std::string& name : scene_.materials) materials_.add(name);
  if (scene_.default_contact) materials_.set_default(*scene_.default_contact);
  for (const ContactSpec& c : scene_.contacts) {
    materials_.set_pair(*materials_.find(c.a), *materials_.find(c.b), c.law);
  }
  // The shifts of a body's periodic images (none but the body itself without periodic axes).
  image_shifts_.assign(1, Vector3::Zero());
  for (std::size_t d = 0; d < 3; ++d) {
    if (!scene_.domain.periodic[d]) continue;
    const double period =
        scene_.domain.box.max[static_cast<int>(d)] - scene_.domain.box.min[static_cast<int>(d)];
    const std::size_t n = image_shifts_.size();
    for (std::size_t k = 0; k < n; ++k) {
      for (const double sign : {-1.0, 1.0}) {
        Vector3 shift = image_shifts_[k];
        shift[static_cast<int>(d)] = sign * period;
        image_shifts_.push_back(shift);
      }
    }
  }
  build_static();
  check_shapes();
  require_invertible_constants();
  generators_.resize(scene_.groups.size());
  if (state == nullptr) {
    for (std::size_t g = 0; g < scene_.groups.size(); ++g) {
      generators_[g].random = scene_.groups[g].generator.seed;
    }
    generate_initial();
  } else {
    restore(*state);
  }
  try {
    engine_ = distribution_ != nullptr
                  ? distribution_->engine(system_, statics_, materials_, scene_.settings)
                  : std::make_unique<SerialEngine>(system_, statics_, materials_, scene_.settings);
  } catch (const SceneError&) {
    throw;
  } catch (const InvalidArgument& e) {
    throw SceneError(scene_.file.string() + ": " + e.what());
  }
  stepper_ = &engine_->stepper();
  if (state != nullptr) {
    stepper_->set_clock(state->t, state->steps);
    stepper_->warm_starts().store(state->warm_keys, state->warm_lambda);
  }
}

void Simulation::build_static() {
  for (std::size_t k = 0; k < scene_.statics.size(); ++k) {
    const StaticSpec& s = scene_.statics[k];
    if (s.until) ++pending_removals_;
    timestep::StaticObject object;
    object.id = k;
    object.shape = s.shape;
    object.pose = s.pose;
    object.material = *materials_.find(s.material);
    try {
      statics_.add(std::move(object));
    } catch (const InvalidArgument& e) {
      throw SceneError(scene_.file.string() + ": static[" + std::to_string(k) + "] (" + s.name +
                       "): " + e.what());
    }
  }
}

void Simulation::check_shapes() const {
  const std::string supported =
      "supported pairs: sphere with any shape, box or capsule with a half-space";
  // Whether bodies of group g can ever touch each other: two of them, one at least dynamic.
  auto self_contact = [&](std::size_t g) {
    const BodyGroup& group = scene_.groups[g];
    return !group.fixed &&
           (group.generator.kind != GeneratorKind::list || group.generator.positions.size() > 1);
  };
  for (std::size_t g = 0; g < scene_.groups.size(); ++g) {
    const ShapeKind a = scene_.groups[g].shape;
    for (std::size_t h = g; h < scene_.groups.size(); ++h) {
      const ShapeKind b = scene_.groups[h].shape;
      if (h == g && !self_contact(g)) continue;
      if (scene_.groups[g].fixed && scene_.groups[h].fixed) continue;
      if (!collision::supported(a, b)) {
        fail(scene_, g,
             "a " + std::string(collision::kind_name(a)) + " of it can touch a " +
                 std::string(collision::kind_name(b)) + " of bodies[" + std::to_string(h) +
                 "], a pair grbd cannot collide (" + supported + ")");
      }
    }
    for (std::size_t s = 0; s < scene_.statics.size(); ++s) {
      const ShapeKind b = collision::kind(scene_.statics[s].shape);
      if (!scene_.groups[g].fixed && !collision::supported(a, b)) {
        fail(scene_, g,
             "a " + std::string(collision::kind_name(a)) + " of it can touch static[" +
                 std::to_string(s) + "] (" + scene_.statics[s].name + ", a " +
                 std::string(collision::kind_name(b)) + "), a pair grbd cannot collide (" +
                 supported + ")");
      }
    }
  }
}

BodyRecord Simulation::body_for(const BodyGroup& g, double radius) const {
  BodyRecord c;
  c.material = *materials_.find(g.material);
  c.flags = g.fixed ? 0 : timestep::kDynamic;
  body::MassProperties mass;
  switch (g.shape) {
    case ShapeKind::box:
      c.shape = collision::Box{g.half_extents};
      mass = body::box_mass_properties(g.half_extents, 1.0);
      break;
    case ShapeKind::capsule:
      c.shape = collision::Capsule{radius, g.half_length};
      mass = body::capsule_mass_properties(radius, 2.0 * g.half_length, 1.0);
      break;
    default:
      c.shape = collision::Sphere{radius};
      mass = body::sphere_mass_properties(radius, 1.0);
      break;
  }
  // Unit density first, then scaled: by the density, or to the given mass.
  const double scale = g.density ? *g.density : *g.mass / mass.mass;
  c.inertia.m = mass.mass * scale;
  c.inertia.K_Theta = mass.M_Theta_S.diagonal() * scale;
  return c;
}

BodyRecord Simulation::make_body(std::size_t group, Random& random) {
  const BodyGroup& g = scene_.groups[group];
  BodyRecord c = body_for(g, g.shape == ShapeKind::box ? 0.0 : g.radius.sample(random));
  c.id = next_id_;
  return c;
}

void Simulation::add_body(BodyRecord record, const body::State& state) {
  // A parallel run makes every body on every process, so that each draws the same numbers and
  // ids, and keeps the bodies it owns.
  if (distribution_ != nullptr && !distribution_->owns(state.q.head<3>())) return;
  record.state = state;
  system_.add(record);
  created_.push_back(std::move(record));
}

void Simulation::generate_initial() {
  for (std::size_t g = 0; g < scene_.groups.size(); ++g) {
    const BodyGroup& group = scene_.groups[g];
    const GeneratorSpec& spec = group.generator;
    if (spec.kind == GeneratorKind::inflow) continue;
    Random random(generators_[g].random);
    const double r_b = largest_bounding_radius(group);
    auto state_at = [&](const Vector3& position) { return initial_state(group, random, position); };
    std::uint64_t made = 0;
    // List and lattice bodies go where they are told: each is checked against the static
    // geometry and, for spheres, against the spheres made before it (earlier groups, earlier
    // positions of a list), so that a scene never starts with bodies inside each other.
    const bool spheres = group.shape == ShapeKind::sphere;
    if (spheres && spec.kind != GeneratorKind::packing) {
      double r_existing = 0.0;
      for (std::size_t i = 0; i < system_.size(); ++i) {
        if (collision::kind(system_.shapes()[i]) == ShapeKind::sphere) {
          r_existing = std::max(r_existing, system_.bounding_radii()[i]);
        }
      }
      scratch_->grid.reset(r_b + std::max(r_b, r_existing));
      scratch_->owner.clear();
      for (std::size_t i = 0; i < system_.size(); ++i) {
        if (collision::kind(system_.shapes()[i]) != ShapeKind::sphere) continue;
        scratch_->grid.insert(system_.states()[i].q.head<3>(), system_.bounding_radii()[i]);
        scratch_->owner.push_back(system_.ids()[i]);
      }
    }
    auto place = [&](const BodyRecord& c, const body::State& x) {
      const Vector3 p = x.q.head<3>();
      const double r = bounding_radius(c);
      if (spheres) {
        const std::int64_t j = scratch_->grid.find(p, r, 1e-6 * r);
        if (j >= 0) {
          std::ostringstream out;
          out << "generator: the body at (" << p.x() << ", " << p.y() << ", " << p.z()
              << ") m overlaps the body with id " << scratch_->owner[static_cast<std::size_t>(j)]
              << ", made before it; move the region or positions apart";
          fail(scene_, g, out.str());
        }
        scratch_->grid.insert(p, r);
        scratch_->owner.push_back(c.id);
      }
      if (c.dynamic()) {
        const auto [gap, s] = static_gap(c.shape, x);
        if (gap < -1e-6 * r) {
          std::ostringstream out;
          out << "generator: the body at (" << p.x() << ", " << p.y() << ", " << p.z()
              << ") m overlaps static[" << s << "] (" << scene_.statics[s].name << ") by " << -gap
              << " m; move the region or positions clear of the static geometry";
          fail(scene_, g, out.str());
        }
      }
      add_body(c, x);
    };
    if (spec.kind == GeneratorKind::list) {
      for (const Vector3& p : spec.positions) {
        const BodyRecord c = make_body(g, random);
        place(c, state_at(p));
        ++next_id_;
        ++made;
      }
    } else if (spec.kind == GeneratorKind::lattice) {
      const double s = spec.spacing > 0.0 ? spec.spacing : 2.0 * r_b;
      if (s < 2.0 * r_b) {
        std::ostringstream out;
        out << "generator.spacing: expected at least twice the largest bounding radius ("
            << 2.0 * r_b << " m) so that no bodies overlap, found " << s;
        fail(scene_, g, out.str());
      }
      const Vector3 extent = spec.region.max - spec.region.min;
      // Sites per axis, with a tolerance of 10⁻⁹ of a site: 80 mm at 4 mm is 20 sites, though
      // 0.08 / 0.004 is 19.999999999999996 in doubles.
      const Eigen::Array3d cells = (extent.array() / s + 1e-9).floor();
      const double capacity = cells.prod();
      if (capacity < 1.0 || (spec.count > 0 && static_cast<double>(spec.count) > capacity)) {
        std::ostringstream out;
        out << "generator.region: holds " << capacity << " lattice sites of spacing " << s
            << " m, fewer than count = " << std::max<std::uint64_t>(spec.count, 1);
        fail(scene_, g, out.str());
      }
      const double n = spec.count > 0 ? static_cast<double>(spec.count) : capacity;
      if (n > static_cast<double>(kMaxBodies)) {
        fail(scene_, g,
             "generator: the lattice would hold " + std::to_string(n) +
                 " bodies, more than 10⁸; give a count or a smaller region");
      }
      // n ≤ 10⁸ sites are used: a row or layer longer than n is cut to n before the conversion
      // (a huge region would overflow the integer), which leaves the sites used unchanged.
      const auto nx = static_cast<std::uint64_t>(std::min(cells.x(), n));
      const auto ny = static_cast<std::uint64_t>(std::min(cells.y(), n));
      require_memory(system_.size() + static_cast<std::size_t>(n), g);
      system_.reserve(system_.size() + static_cast<std::size_t>(n));
      for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(n); ++k) {
        const Vector3 site(static_cast<double>(k % nx), static_cast<double>((k / nx) % ny),
                           static_cast<double>(k / (nx * ny)));
        BodyRecord c = make_body(g, random);
        const double r_i = bounding_radius(c);
        // A shift of at most s/2 − r_i per coordinate keeps neighbours apart and the body
        // inside the region.
        const double amplitude = spec.jitter * (0.5 * s - r_i);
        Vector3 p = spec.region.min + (site.array() + 0.5).matrix() * s;
        for (int d = 0; d < 3; ++d) p[d] += amplitude * (2.0 * random.uniform() - 1.0);
        place(c, state_at(p));
        ++next_id_;
        ++made;
      }
    } else {  // packing: random sequential addition, largest bodies first
      const Vector3 extent = spec.region.max - spec.region.min;
      if (spec.count > kMaxBodies) {
        fail(scene_, g,
             "generator.count: expected at most 10⁸ bodies, found " + std::to_string(spec.count));
      }
      require_memory(system_.size() + spec.count, g);
      std::vector<BodyRecord> bodies;
      bodies.reserve(spec.count);
      double volume = 0.0;
      for (std::uint64_t k = 0; k < spec.count; ++k) {
        bodies.push_back(make_body(g, random));
        const double r = bounding_radius(bodies.back());
        volume += 4.0 / 3.0 * M_PI * r * r * r;
        ++next_id_;
      }
      const double fraction = volume / extent.prod();
      if (fraction > 0.5) {
        std::ostringstream out;
        out << "generator: " << spec.count << " bounding spheres fill " << fraction
            << " of the region; random sequential addition cannot exceed about 0.38: lower count "
               "or enlarge the region";
        fail(scene_, g, out.str());
      }
      // Ids follow the order of creation; placement goes largest first.
      std::vector<std::size_t> order(bodies.size());
      for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
      std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return radius_of(bodies[a]) > radius_of(bodies[b]);
      });
      double r_existing = 0.0;
      for (double r : system_.bounding_radii()) r_existing = std::max(r_existing, r);
      OverlapGrid grid(r_b + std::max(r_b, r_existing));
      for (std::size_t i = 0; i < system_.size(); ++i) {
        grid.insert(system_.states()[i].q.head<3>(), system_.bounding_radii()[i]);
      }
      std::vector<body::State> states(bodies.size());
      for (std::size_t k : order) {
        const BodyRecord& c = bodies[k];
        const double r = bounding_radius(c);
        const Vector3 room = extent - Vector3::Constant(2.0 * r);
        if ((room.array() < 0.0).any()) {
          fail(scene_, g,
               "generator.region: smaller than a body of bounding radius " + std::to_string(r) +
                   " m");
        }
        bool placed = false;
        for (int attempt = 0; attempt < spec.max_attempts && !placed; ++attempt) {
          Vector3 p;
          for (int d = 0; d < 3; ++d) p[d] = spec.region.min[d] + r + room[d] * random.uniform();
          if (grid.overlaps(p, r)) continue;
          const body::State x = state_at(p);
          if (c.dynamic() && static_gap(c.shape, x).first < 0.0) continue;  // inside statics
          grid.insert(p, r);
          states[k] = x;
          placed = true;
        }
        if (!placed) {
          std::ostringstream out;
          out << "generator: could not place a body without overlap after max_attempts = "
              << spec.max_attempts << " tries (" << made << " of " << spec.count
              << " placed, volume fraction " << fraction << "): lower count or enlarge the region";
          fail(scene_, g, out.str());
        }
        ++made;
      }
      system_.reserve(system_.size() + bodies.size());
      for (std::size_t k = 0; k < bodies.size(); ++k) add_body(bodies[k], states[k]);
    }
    generators_[g].random = random.state();
    generators_[g].created = made;
  }
}

void Simulation::inflow() {
  backlog_ = 0;
  const double t = stepper_->time();
  for (std::size_t g = 0; g < scene_.groups.size(); ++g) {
    const BodyGroup& group = scene_.groups[g];
    const GeneratorSpec& spec = group.generator;
    if (spec.kind != GeneratorKind::inflow || t + scene_.settings.dt <= spec.start) continue;
    // Bodies due by the end of this step (or by stop): rate × (t_end − start), at most count
    // (10⁻⁶ of a body absorbs the round-off of t, a sum of steps). A backlog is still delivered
    // after stop.
    double t_end = t + scene_.settings.dt;
    if (spec.stop > 0.0) t_end = std::min(t_end, spec.stop);
    // In floating point, clamped before the conversion: a rate · time beyond 2⁶⁴ would be
    // undefined as an integer. No run places 2⁶² bodies; the rest waits as backlog.
    const double owed = std::floor(spec.rate * (t_end - spec.start) + 1e-6);
    const double cap = spec.count > 0 ? static_cast<double>(spec.count) : 0x1p62;
    const auto due = static_cast<std::uint64_t>(std::clamp(owed, 0.0, cap));
    GeneratorState& state = generators_[g];
    if (due <= state.created) continue;
    Random random(state.random);
    const double r_b = largest_bounding_radius(group);
    double r_existing = 0.0;
    const Vector3 lo = spec.region.min;
    const Vector3 hi = spec.region.max;
    // The bodies that reach into the region: one pass over the system, O(N) like the step
    // itself, into buffers kept between steps.
    // (In a parallel run, the owned bodies of every process, so that every process places the
    // same bodies.)
    std::vector<Vector4>& near = scratch_->near;
    near.clear();
    for (std::size_t i = 0; i < system_.owned_count(); ++i) {
      const double r = system_.bounding_radii()[i];
      const double reach = r + r_b;
      // The body and, in a periodic domain, its images across the periodic boundaries.
      for (const Vector3& shift : image_shifts_) {
        const Vector3 c = system_.states()[i].q.head<3>() + shift;
        if ((c.array() >= lo.array() - reach).all() && (c.array() <= hi.array() + reach).all()) {
          near.emplace_back(c.x(), c.y(), c.z(), r);
        }
      }
    }
    if (distribution_ != nullptr) gather_near(near);
    for (const Vector4& sphere : near) r_existing = std::max(r_existing, sphere[3]);
    OverlapGrid& grid = scratch_->grid;
    grid.reset(r_b + std::max(r_b, r_existing));
    for (const Vector4& sphere : near) grid.insert(sphere.head<3>(), sphere[3]);
    while (state.created < due) {
      // The body's radius and its tries are drawn from the saved state, so a body that does not
      // fit now is drawn again, identically, at the next step.
      Random trial = random;
      BodyRecord c = make_body(g, trial);
      const double r = bounding_radius(c);
      const Vector3 room = (hi - lo) - Vector3::Constant(2.0 * r);
      if ((room.array() < 0.0).any()) {
        fail(
            scene_, g,
            "generator.region: smaller than a body of bounding radius " + std::to_string(r) + " m");
      }
      bool placed = false;
      Vector3 p;
      body::State x;
      for (int attempt = 0; attempt < spec.max_attempts && !placed; ++attempt) {
        for (int d = 0; d < 3; ++d) p[d] = lo[d] + r + room[d] * trial.uniform();
        if (grid.overlaps(p, r)) continue;
        x = initial_state(group, trial, p);
        placed = !c.dynamic() || statics_.size() == 0 || static_gap(c.shape, x).first >= 0.0;
      }
      if (!placed) {
        backlog_ += due - state.created;
        break;
      }
      grid.insert(p, r);
      add_body(c, x);
      ++next_id_;
      ++state.created;
      random = trial;
    }
    state.random = random.state();
  }
}

void Simulation::gather_near(std::vector<Vector4>& near) {
  std::vector<std::vector<std::byte>>& all = scratch_->gathered;
  distribution_->communicator().all_gather(std::as_bytes(std::span(near)), all);
  near.clear();
  for (const std::vector<std::byte>& part : all) {
    const std::size_t n = part.size() / sizeof(Vector4);
    const std::size_t at = near.size();
    near.resize(at + n);
    if (n > 0) std::memcpy(static_cast<void*>(near.data() + at), part.data(), n * sizeof(Vector4));
  }
}

void Simulation::outlet() {
  if (!scene_.domain.enabled) return;
  leaving_.clear();
  const Region& box = scene_.domain.box;
  const auto states = system_.states();
  const auto& periodic = scene_.domain.periodic;
  for (std::size_t i = 0; i < system_.owned_count(); ++i) {
    const Vector3 c = states[i].q.head<3>();
    for (int d = 0; d < 3; ++d) {
      // Along a periodic axis a body is wrapped, never removed.
      if (!periodic[static_cast<std::size_t>(d)] && (c[d] < box.min[d] || c[d] > box.max[d])) {
        leaving_.push_back(i);
        break;
      }
    }
  }
  double mass = 0.0;  // of this process's leaving bodies, in a parallel run
  for (std::size_t i : leaving_)
    (distribution_ == nullptr ? removed_mass_ : mass) += system_.inertia()[i].m;
  if (!leaving_.empty()) {
    system_.remove(leaving_);
    engine_->bodies_changed();
  }
  if (distribution_ == nullptr) {
    removed_ += leaving_.size();
    return;
  }
  // The counts of the whole run, the same on every process (the mass summed in rank order).
  std::vector<double> sums{static_cast<double>(leaving_.size()), mass};
  distribution_->communicator().sum(sums);
  removed_ += static_cast<std::uint64_t>(sums[0]);
  removed_mass_ += sums[1];
}

// [remove statics]
// The static objects whose time is up (key until) are gone before the step that starts at
// t ≥ until — the same step on every process and after a restart, since t is the stepper's clock.
void Simulation::remove_expired_statics() {
  if (pending_removals_ == 0) return;
  const double t = stepper_->time();
  for (std::size_t k = 0; k < scene_.statics.size(); ++k) {
    const std::optional<double>& until = scene_.statics[k].until;
    if (until && t >= *until && statics_.remove(k)) --pending_removals_;
  }
}
// [remove statics]

timestep::StepReport Simulation::step() {
  remove_expired_statics();
  const std::uint64_t before = system_.owned_count();
  inflow();
  if (system_.owned_count() != before) engine_->bodies_changed();
  timestep::StepReport report = engine_->step();
  outlet();
  return report;
}

SimulationState Simulation::save() const {
  SimulationState s;
  s.t = stepper_->time();
  s.steps = stepper_->steps();
  s.next_id = next_id_;
  s.removed = removed_;
  s.removed_mass = removed_mass_;
  s.bodies.reserve(system_.owned_count());
  for (std::size_t i = 0; i < system_.owned_count(); ++i) s.bodies.push_back(system_.record(i));
  const timestep::WarmStartTable& warm = stepper_->warm_starts();
  s.warm_keys.assign(warm.keys().begin(), warm.keys().end());
  s.warm_lambda.assign(warm.lambda().begin(), warm.lambda().end());
  s.generators = generators_;
  return s;
}

void Simulation::restore(const SimulationState& state) {
  const auto refuse = [](const std::string& what) { throw StateError(what); };
  if (state.generators.size() != scene_.groups.size()) {
    refuse("expected the state of a scene with " + std::to_string(scene_.groups.size()) +
           " body groups, found " + std::to_string(state.generators.size()));
  }
  if (state.warm_keys.size() != state.warm_lambda.size()) {
    refuse("the warm-start arrays differ in length");
  }
  // The clock counts steps of this scene's Δt: t and steps must agree to half a step.
  const double dt = scene_.settings.dt;
  if (!(std::abs(state.t / dt - static_cast<double>(state.steps)) <= 0.5)) {
    refuse("t = " + format_number(state.t) + " s and steps = " + std::to_string(state.steps) +
           " do not fit the scene's dt = " + format_number(dt) +
           " s (t / dt = " + format_number(state.t / dt) + ")");
  }
  for (std::size_t g = 0; g < scene_.groups.size(); ++g) {
    const GeneratorSpec& spec = scene_.groups[g].generator;
    const std::uint64_t count =
        spec.kind == GeneratorKind::list ? spec.positions.size() : spec.count;
    if (count > 0 && state.generators[g].created > count) {
      refuse("group " + std::to_string(g) + " (" + scene_.groups[g].name + ") has created " +
             std::to_string(state.generators[g].created) + " bodies, more than its count " +
             std::to_string(count));
    }
  }
  generators_ = state.generators;
  next_id_ = state.next_id;
  removed_ = state.removed;
  removed_mass_ = state.removed_mass;
  system_.reserve(state.bodies.size());
  for (std::size_t i = 0; i < state.bodies.size(); ++i) {
    const BodyRecord& c = state.bodies[i];
    if (c.material >= materials_.size()) {
      refuse("body " + std::to_string(c.id) + " has material " + std::to_string(c.material) +
             ", the scene has " + std::to_string(materials_.size()));
    }
    if (c.id >= next_id_) {
      refuse("body " + std::to_string(c.id) +
             " has an id not below next_id = " + std::to_string(next_id_));
    }
    require_from_scene(c);
    if (distribution_ != nullptr && !distribution_->owns(c.state.q.head<3>())) continue;
    try {
      system_.add(c);
    } catch (const InvalidArgument& e) {
      refuse(e.what());
    }
  }
}

// A body of the state must be one that a group of the scene makes: its shape, material and
// fixedness, a size the group's distribution can draw, and the mass and moments the group's
// density or mass give it (to 10⁻¹² relative: a damaged or foreign value is refused).
void Simulation::require_from_scene(const BodyRecord& c) const {
  const auto close = [](double a, double b) {
    return std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b));
  };
  const ShapeKind shape = collision::kind(c.shape);
  const double radius = radius_of(c);
  for (const BodyGroup& g : scene_.groups) {
    if (g.shape != shape || *materials_.find(g.material) != c.material || g.fixed == c.dynamic())
      continue;
    const auto* box = std::get_if<collision::Box>(&c.shape);
    if (box ? g.half_extents != box->half_extents
            : !(radius >= g.radius.min() && radius <= g.radius.max()))
      continue;
    if (const auto* capsule = std::get_if<collision::Capsule>(&c.shape);
        capsule != nullptr && g.half_length != capsule->half_length)
      continue;
    const BodyRecord expected = body_for(g, radius);
    if (close(expected.inertia.m, c.inertia.m) &&
        close(expected.inertia.K_Theta[0], c.inertia.K_Theta[0]) &&
        close(expected.inertia.K_Theta[1], c.inertia.K_Theta[1]) &&
        close(expected.inertia.K_Theta[2], c.inertia.K_Theta[2])) {
      return;
    }
  }
  throw StateError(
      "body " + std::to_string(c.id) + " (a " + std::string(collision::kind_name(shape)) +
      " of radius " + format_number(radius) + " m, mass " + format_number(c.inertia.m) +
      " kg, moments (" + format_number(c.inertia.K_Theta[0]) + ", " +
      format_number(c.inertia.K_Theta[1]) + ", " + format_number(c.inertia.K_Theta[2]) +
      ") kg m²) is not a body that a group "
      "of the scene makes: no group has its shape, material, size and the mass "
      "and inertia its density or mass gives");
}

}  // namespace grbd::scene
