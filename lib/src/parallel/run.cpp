/// \file
/// \brief `mpirun -np P grbd run`: a scene's run on many processes, with rank 0 writing the
/// output and the checkpoints from the parts of every process.

#include "grbd/parallel/run.hpp"

#include <algorithm>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "grbd/core/checks.hpp"
#include "grbd/core/collectives.hpp"
#include "grbd/io/checkpoint.hpp"
#include "grbd/io/output.hpp"
#include "grbd/parallel/bisection.hpp"
#include "grbd/parallel/decomposition.hpp"

namespace grbd::parallel {

namespace {

// [send to owners]
// After a restart read in slabs (io::read_checkpoint): every body goes to the process that owns
// its centre, every warm start to the one that solves its contact — the owner of side a, or of
// side b when side a is a static object (solves_contact()). Who owns a body is known where its
// row was read; a warm start meets that knowledge at a directory process, id mod P: three
// exchanges among all processes, each carrying O(N/P) rows. The rows keep the file's order.
void send_to_owners(const Communicator& comm, const SceneDecomposition& decomposition,
                    scene::SimulationState& state) {
  const int P = comm.size();
  if (P == 1) return;
  const auto to = [&](std::uint64_t id) { return static_cast<std::size_t>(id % std::uint64_t(P)); };
  struct Owner {
    std::uint64_t id;
    std::int64_t rank;
  };
  using Warm = timestep::WarmRow;
  const auto n = static_cast<std::size_t>(P);
  std::vector<std::vector<std::byte>> bodies(n), owners(n), warm(n), received;
  timestep::PackedBody packed;
  for (const timestep::BodyRecord& body : state.bodies) {
    const int owner = decomposition.owner(body.state.q.head<3>());
    timestep::pack(body, packed);
    collective::put(bodies[static_cast<std::size_t>(owner)], packed);
    collective::put(owners[to(body.id)], Owner{body.id, owner});
  }
  for (std::size_t k = 0; k < state.warm_keys.size(); ++k) {
    const Vector3& l = state.warm_lambda[k];
    const timestep::ContactKey& key = state.warm_keys[k];
    collective::put(warm[to(solving_side(key))], Warm{key, {l[0], l[1], l[2]}});
  }
  collective::exchange_with_all(comm, bodies, received);
  state.bodies.clear();
  for (const timestep::PackedBody& row : collective::rows_of<timestep::PackedBody>(received)) {
    state.bodies.push_back(timestep::unpack(row));
  }
  // The directory: the owner of each body whose id it holds, and the warm starts of those ids.
  collective::exchange_with_all(comm, owners, received);
  const std::vector<Owner> directory = [&] {
    std::vector<Owner> d = collective::rows_of<Owner>(received);
    std::sort(d.begin(), d.end(), [](const Owner& a, const Owner& b) { return a.id < b.id; });
    return d;
  }();
  collective::exchange_with_all(comm, warm, received);
  std::vector<Warm> rows = collective::rows_of<Warm>(received);
  for (std::vector<std::byte>& out : warm) out.clear();
  for (const Warm& w : rows) {
    const std::uint64_t id = solving_side(w.key);
    const auto it = std::lower_bound(directory.begin(), directory.end(), id,
                                     [](const Owner& o, std::uint64_t x) { return o.id < x; });
    // A warm start of a body the checkpoint does not hold is of no use to anyone.
    if (it == directory.end() || it->id != id) continue;
    collective::put(warm[static_cast<std::size_t>(it->rank)], w);
  }
  collective::exchange_with_all(comm, warm, received);
  state.warm_keys.clear();
  state.warm_lambda.clear();
  for (const Warm& w : collective::rows_of<Warm>(received)) {
    state.warm_keys.push_back(w.key);
    state.warm_lambda.emplace_back(w.lambda[0], w.lambda[1], w.lambda[2]);
  }
}
// [send to owners]

// The skin of the parallel step: the scene's, or half its tolerance radius.
double skin_of(const timestep::StepSettings& s) {
  return s.skin > 0.0 ? s.skin : 0.5 * s.tolerance_radius;
}

double largest_radius(const scene::Scene& scene) {
  double r = 0.0;
  for (const scene::BodyGroup& g : scene.groups) r = std::max(r, scene::largest_bounding_radius(g));
  return r;
}

// The scene's partition of `box` for P processes, before any balance.
std::unique_ptr<Partition> make_partition(int processes, const scene::Scene& scene,
                                          const Box& box) {
  const std::array<bool, 3>& periodic = scene.domain.periodic;
  if (scene.parallel.partition == scene::ParallelSpec::Partition::bisection) {
    return std::make_unique<BisectionTree>(box, processes, periodic);
  }
  return std::make_unique<CartesianGrid>(box, grid_dims(processes, box.sizes()), periodic);
}

}  // namespace

Box decomposition_box(const scene::Scene& scene) {
  const scene::Region region =
      scene.domain.enabled ? scene.domain.box : io::static_surface(scene).bounds;
  return Box(region.min, region.max);
}

SceneDecomposition::SceneDecomposition(const Communicator& comm, const scene::Scene& scene)
    : SceneDecomposition(comm, scene, decomposition_box(scene)) {}

SceneDecomposition::SceneDecomposition(const Communicator& comm, const scene::Scene& scene,
                                       const Box& box)
    : comm_(comm),
      partition_(make_partition(comm.size(), scene, box)),
      parallel_{largest_radius(scene), scene.parallel.average_every, scene.parallel.rebalance_every,
                scene.parallel.imbalance} {
  // Along a periodic axis the images one period away must hold every contact (a body within reach
  // of another through two periods would need more), and no body may reach its own image.
  timestep::StepSettings s = scene.settings;
  s.skin = skin_of(s);
  const double reach = contact_reach(parallel_.max_radius, ghost_margin(s));
  const char* axes = "xyz";
  for (int d = 0; d < 3; ++d) {
    const double period = scene.domain.box.max[d] - scene.domain.box.min[d];
    if (scene.domain.periodic[static_cast<std::size_t>(d)] && !(period > reach)) {
      throw scene::SceneError(scene.file.string() + ": [simulation] periodic: the domain is " +
                              format_number(period) + " m along " + axes[d] +
                              ", expected more than the reach of a contact, " +
                              format_number(reach) + " m (two largest radii, margin and skin)");
    }
  }
}

std::unique_ptr<scene::StepEngine> SceneDecomposition::engine(
    timestep::BodySystem& system, const timestep::StaticGeometry& statics,
    const timestep::MaterialTable& materials, const timestep::StepSettings& settings) const {
  timestep::StepSettings s = settings;
  s.skin = skin_of(s);
  auto engine = std::make_unique<ParallelStepper>(comm_, *partition_, system, statics, materials, s,
                                                  parallel_);
  engine_ = engine.get();
  return engine;
}

void SceneDecomposition::redistribute(scene::SimulationState& state) const {
  send_to_owners(comm_, *this, state);
}

namespace {
double partition_kind(const Partition& partition) {
  return dynamic_cast<const BisectionTree*>(&partition) != nullptr ? 1.0 : 0.0;
}
}  // namespace

std::vector<double> SceneDecomposition::state() const {
  const Partition& partition = engine_ != nullptr ? engine_->partition() : *partition_;
  std::vector<double> state{static_cast<double>(comm_.size()), partition_kind(partition)};
  const std::vector<double> cuts = partition.cuts();
  state.insert(state.end(), cuts.begin(), cuts.end());
  return state;
}

void SceneDecomposition::restore(std::span<const double> state) {
  if (state.size() < 2 || state[0] != static_cast<double>(comm_.size()) ||
      state[1] != partition_kind(*partition_)) {
    return;
  }
  partition_ = partition_->with_cuts(state.subspan(2));
}

bool needs_decomposition(const scene::Scene& scene, const Communicator& comm) {
  return comm.size() > 1 || scene.domain.any_periodic();
}

io::RunResult run(const scene::Scene& scene, const io::RunOptions& options,
                  const Communicator& comm) {
  io::MakeDistribution make;
  if (needs_decomposition(scene, comm)) {
    make = [&]() -> std::unique_ptr<scene::Distribution> {
      return std::make_unique<SceneDecomposition>(comm, scene);
    };
  }
  return io::run(scene, options, comm, make);
}

}  // namespace grbd::parallel
