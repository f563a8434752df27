/// \file
/// \brief `mpirun -np P grbd run`: a scene's run on many processes, with rank 0 writing the
/// output and the checkpoints from the parts of every process.

#include "grbd/parallel/run.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <exception>
#include <new>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "grbd/core/checks.hpp"
#include "grbd/io/checkpoint.hpp"
#include "grbd/io/output.hpp"
#include "grbd/parallel/bisection.hpp"
#include "grbd/parallel/decomposition.hpp"
#include "grbd/parallel/mpi.hpp"
#include "io/collective.hpp"

namespace grbd::parallel {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The kinds of error a process reports to the others, so that each throws the same kind (the
// command line's exit code depends on it).
enum class ErrorKind : std::uint8_t { file_conflict, io, scene, state, memory, other };

[[noreturn]] void rethrow(ErrorKind kind, const std::string& message) {
  switch (kind) {
    case ErrorKind::file_conflict:
      throw io::FileConflict(message);
    case ErrorKind::io:
      throw io::IoError(message);
    case ErrorKind::scene:
      throw scene::SceneError(message);
    case ErrorKind::state:
      throw scene::StateError(message);
    case ErrorKind::memory:
      throw std::bad_alloc();
    case ErrorKind::other:
      break;
  }
  throw Error(message);
}

// [agreed]
// Runs `work` on this process; when it throws here or on another process, every process throws
// the error of the lowest rank that had one (collective). The way an error that only some
// processes find — a file only rank 0 writes, a body only its owner checks — ends them all alike.
template <class Work>
void agreed(const Communicator& comm, Work&& work) {
  std::vector<std::byte> mine;
  const auto report = [&](ErrorKind kind, const std::string& message) {
    mine.resize(1 + message.size());
    mine[0] = static_cast<std::byte>(kind);
    std::memcpy(mine.data() + 1, message.data(), message.size());
  };
  try {
    work();
  } catch (const io::FileConflict& e) {
    report(ErrorKind::file_conflict, e.what());
  } catch (const io::IoError& e) {
    report(ErrorKind::io, e.what());
  } catch (const scene::SceneError& e) {
    report(ErrorKind::scene, e.what());
  } catch (const scene::StateError& e) {
    report(ErrorKind::state, e.what());
  } catch (const std::bad_alloc&) {
    report(ErrorKind::memory, "out of memory");
  } catch (const std::exception& e) {
    report(ErrorKind::other, e.what());
  }
  const std::string error =
      mine.empty() ? std::string()
                   : std::string(reinterpret_cast<const char*>(mine.data()) + 1, mine.size() - 1);
  if (comm.agree(mine.empty(), error, kAgreementPatience)) return;
  std::vector<std::vector<std::byte>> all;
  comm.all_gather(mine, all);
  // An error every process met alike (a file they read together) needs no rank in its message.
  const bool alike =
      std::all_of(all.begin(), all.end(), [&](const auto& e) { return e == all[0]; });
  for (std::size_t r = 0; r < all.size(); ++r) {
    if (all[r].empty()) continue;
    const auto kind = static_cast<ErrorKind>(all[r][0]);
    std::string message(all[r].size() - 1, '\0');
    std::memcpy(message.data(), all[r].data() + 1, message.size());
    if (comm.size() > 1 && !alike) message = "rank " + std::to_string(r) + ": " + message;
    rethrow(kind, message);
  }
}
// [agreed]

// A trivially copyable row appended to a message.
template <class Row>
void put(std::vector<std::byte>& out, const Row& row) {
  static_assert(std::is_trivially_copyable_v<Row>);
  const std::size_t at = out.size();
  out.resize(at + sizeof(Row));
  std::memcpy(out.data() + at, &row, sizeof(Row));
}

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
  using Warm = io::collective::WarmRow;
  const auto n = static_cast<std::size_t>(P);
  std::vector<std::vector<std::byte>> bodies(n), owners(n), warm(n), received;
  timestep::PackedBody packed;
  for (const timestep::BodyRecord& body : state.bodies) {
    const int owner = decomposition.owner(body.state.q.head<3>());
    timestep::pack(body, packed);
    put(bodies[static_cast<std::size_t>(owner)], packed);
    put(owners[to(body.id)], Owner{body.id, owner});
  }
  const auto solver_side = [](const timestep::ContactKey& key) {
    return (key.a & timestep::kStaticTag) != 0 ? key.b : key.a;
  };
  for (std::size_t k = 0; k < state.warm_keys.size(); ++k) {
    const Vector3& l = state.warm_lambda[k];
    const timestep::ContactKey& key = state.warm_keys[k];
    put(warm[to(solver_side(key))], Warm{key, {l[0], l[1], l[2]}});
  }
  io::collective::exchange_with_all(comm, bodies, received);
  state.bodies.clear();
  for (const timestep::PackedBody& row : io::collective::rows_of<timestep::PackedBody>(received)) {
    state.bodies.push_back(timestep::unpack(row));
  }
  // The directory: the owner of each body whose id it holds, and the warm starts of those ids.
  io::collective::exchange_with_all(comm, owners, received);
  const std::vector<Owner> directory = [&] {
    std::vector<Owner> d = io::collective::rows_of<Owner>(received);
    std::sort(d.begin(), d.end(), [](const Owner& a, const Owner& b) { return a.id < b.id; });
    return d;
  }();
  io::collective::exchange_with_all(comm, warm, received);
  std::vector<Warm> rows = io::collective::rows_of<Warm>(received);
  for (std::vector<std::byte>& out : warm) out.clear();
  for (const Warm& w : rows) {
    const std::uint64_t id = solver_side(w.key);
    const auto it = std::lower_bound(directory.begin(), directory.end(), id,
                                     [](const Owner& o, std::uint64_t x) { return o.id < x; });
    // A warm start of a body the checkpoint does not hold is of no use to anyone.
    if (it == directory.end() || it->id != id) continue;
    put(warm[static_cast<std::size_t>(it->rank)], w);
  }
  io::collective::exchange_with_all(comm, warm, received);
  state.warm_keys.clear();
  state.warm_lambda.clear();
  for (const Warm& w : io::collective::rows_of<Warm>(received)) {
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
  const timestep::StepSettings& s = scene.settings;
  const double reach =
      2.0 * parallel_.max_radius + s.contact_tolerance * s.tolerance_radius + skin_of(s);
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

io::RunResult run(const scene::Scene& scene, const io::RunOptions& options,
                  const Communicator& comm) {
  const auto start = std::chrono::steady_clock::now();
  const bool root = comm.rank() == 0;
  agreed(comm, [&] {
    if (!root) return;
    io::check_run_files(scene, options);
    io::clear_stale_stop_file(options);
  });
  std::optional<SceneDecomposition> decomposition;
  agreed(comm, [&] { decomposition.emplace(comm, scene); });
  io::RunResult result;
  std::unique_ptr<scene::Simulation> simulation;
  std::unique_ptr<io::OutputFile> output;
  // Every process writes its own bodies and contacts into the one file (parallel HDF5).
  const auto write_record = [&](scene::Simulation& sim) {
    io::RecordPart part;
    io::collect_record(sim, scene.output.contacts, part);
    agreed(comm, [&] { output->write_record(sim.stepper().time(), sim.stepper().steps(), part); });
  };
  if (options.restart) {
    io::Checkpoint checkpoint;
    agreed(comm, [&] { checkpoint = io::read_checkpoint(comm, *options.restart); });
    if (const std::string difference =
            io::scene_difference(checkpoint.scene_text, scene.text, scene.file);
        root && !difference.empty() && options.on_warning) {
      options.on_warning(difference);
    }
    send_to_owners(comm, *decomposition, checkpoint.state);
    agreed(comm, [&] {
      simulation = io::restored_simulation(scene, checkpoint, *options.restart, &*decomposition);
    });
    std::vector<std::byte> exists(1, std::byte{0});
    if (root) {
      std::error_code error;
      exists[0] = static_cast<std::byte>(std::filesystem::exists(options.output, error));
    }
    comm.broadcast(exists, 0);
    if (exists[0] == std::byte{0}) {
      // A new output: its body table starts with every body of the checkpoint.
      for (std::size_t i = 0; i < simulation->system().owned_count(); ++i) {
        simulation->created().push_back(simulation->system().record(i));
      }
    }
    // Rank 0 checks that an output it reopens is this run's with the bodies it holds.
    agreed(comm, [&] {
      output = exists[0] != std::byte{0}
                   ? std::make_unique<io::OutputFile>(
                         options.output, scene, checkpoint.output,
                         io::RunIdentity{checkpoint.scene_text, checkpoint.state.bodies}, comm)
                   : std::make_unique<io::OutputFile>(options.output, scene, comm);
    });
  } else {
    agreed(comm, [&] {
      simulation = std::make_unique<scene::Simulation>(scene, nullptr, *decomposition);
    });
    agreed(comm, [&] { output = std::make_unique<io::OutputFile>(options.output, scene, comm); });
    write_record(*simulation);
  }
  scene::Simulation& sim = *simulation;
  const std::uint64_t every = scene.output.every;
  const std::uint64_t checkpoint_every = scene.checkpoint.every;
  std::uint64_t saved_at = ~std::uint64_t{0};
  const auto save = [&] {
    if (saved_at == sim.stepper().steps()) return;
    saved_at = sim.stepper().steps();
    const auto t0 = std::chrono::steady_clock::now();
    agreed(comm, [&] {
      output->flush(sim);
      io::write_checkpoint(comm, options.checkpoint,
                           io::Checkpoint{sim.save(), output->position(), scene.text});
    });
    ++result.checkpoints;
    result.output_seconds += seconds_since(t0);
  };
  bool recorded = !options.restart || (every > 0 && sim.stepper().steps() % every == 0);
  while (true) {
    // [agreed stop]
    // The stop and the end, agreed by every process at a step boundary.
    const bool by_file = root && io::stop_requested(options);
    const bool stop = by_file || (options.stop != nullptr && *options.stop != 0);
    std::vector<double> stops{stop ? 1.0 : 0.0, by_file ? 1.0 : 0.0};
    comm.max(stops);
    if (stops[0] > 0.0) {
      result.interrupted = true;
      result.stop_file = stops[1] > 0.0;
      break;
    }
    if (sim.finished()) break;
    // [agreed stop]
    const auto t0 = std::chrono::steady_clock::now();
    timestep::StepReport report;
    try {
      report = sim.step();
    } catch (const std::exception& e) {
      // The other processes wait in the step's exchanges: only an abort ends them. The output
      // holds every record before this step (each is counted once it is complete).
      abort_run(std::string("the run failed: ") + e.what(), 1);
    }
    result.step_seconds += seconds_since(t0);
    ++result.steps;
    std::uint64_t bodies[1] = {sim.system().owned_count()};
    comm.sum(bodies);
    output->add_step(report, bodies[0]);
    recorded = false;
    const std::uint64_t step = sim.stepper().steps();
    if (every > 0 && step % every == 0) {
      const auto t1 = std::chrono::steady_clock::now();
      write_record(sim);
      result.output_seconds += seconds_since(t1);
      recorded = true;
    }
    if (checkpoint_every > 0 && step % checkpoint_every == 0) save();
    if (root && options.on_step) options.on_step(sim, report, bodies[0]);
  }
  save();
  if (!recorded && !result.interrupted) {
    const auto t1 = std::chrono::steady_clock::now();
    write_record(sim);
    result.output_seconds += seconds_since(t1);
  }
  agreed(comm, [&] { output->close(sim); });
  if (root && result.stop_file) io::remove_stop_file(options);
  result.records = output->position().records;
  result.rebalances = decomposition->rebalances();
  result.seconds = seconds_since(start);
  return result;
}

}  // namespace grbd::parallel
