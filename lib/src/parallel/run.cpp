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
#include "grbd/parallel/mpi.hpp"

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
  if (comm.all(mine.empty())) return;
  std::vector<std::vector<std::byte>> all;
  comm.all_gather(mine, all);
  for (std::size_t r = 0; r < all.size(); ++r) {
    if (all[r].empty()) continue;
    const auto kind = static_cast<ErrorKind>(all[r][0]);
    std::string message(all[r].size() - 1, '\0');
    std::memcpy(message.data(), all[r].data() + 1, message.size());
    if (comm.size() > 1) message = "rank " + std::to_string(r) + ": " + message;
    rethrow(kind, message);
  }
}
// [agreed]

// Plain values into a byte buffer and back.
template <class T>
void put(std::vector<std::byte>& out, const T* values, std::size_t n) {
  static_assert(std::is_trivially_copyable_v<T>);
  const std::size_t at = out.size();
  out.resize(at + n * sizeof(T));
  if (n > 0) std::memcpy(out.data() + at, values, n * sizeof(T));
}

class Reader {
 public:
  explicit Reader(const std::vector<std::byte>& bytes) : bytes_(bytes) {}
  template <class T>
  void get(T* values, std::size_t n) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (at_ + n * sizeof(T) > bytes_.size()) throw Error("a process sent a truncated message");
    if (n > 0) std::memcpy(values, bytes_.data() + at_, n * sizeof(T));
    at_ += n * sizeof(T);
  }
  template <class T>
  T value() {
    T v{};
    get(&v, 1);
    return v;
  }

 private:
  const std::vector<std::byte>& bytes_;
  std::size_t at_ = 0;
};

void put_records(std::vector<std::byte>& out, const std::vector<timestep::BodyRecord>& records) {
  const std::uint64_t n = records.size();
  put(out, &n, 1);
  const std::size_t at = out.size();
  out.resize(at + n * timestep::kPackedBodyBytes);
  for (std::size_t i = 0; i < records.size(); ++i) {
    timestep::pack(records[i], std::span<std::byte, timestep::kPackedBodyBytes>(
                                   out.data() + at + i * timestep::kPackedBodyBytes,
                                   timestep::kPackedBodyBytes));
  }
}

void get_records(Reader& in, std::vector<timestep::BodyRecord>& records) {
  const auto n = in.value<std::uint64_t>();
  timestep::PackedBody packed;
  for (std::uint64_t i = 0; i < n; ++i) {
    in.get(packed.data(), packed.size());
    records.push_back(timestep::unpack(packed));
  }
}

// The parts of a record (or only the created bodies) from every process, on rank 0.
std::vector<io::RecordPart> gather_parts(const Communicator& comm, io::RecordPart& part) {
  std::vector<std::byte> bytes;
  const std::uint64_t counts[2] = {part.bodies.size(), part.contacts.size()};
  put(bytes, counts, 2);
  put(bytes, part.bodies.data(), part.bodies.size());
  put(bytes, part.contacts.data(), part.contacts.size());
  put_records(bytes, part.created);
  part.created.clear();
  std::vector<std::vector<std::byte>> all;
  comm.gather(bytes, all, 0);
  std::vector<io::RecordPart> parts(all.size());
  for (std::size_t r = 0; r < all.size(); ++r) {
    Reader in(all[r]);
    std::uint64_t n[2];
    in.get(n, 2);
    parts[r].bodies.resize(n[0]);
    in.get(parts[r].bodies.data(), n[0]);
    parts[r].contacts.resize(n[1]);
    in.get(parts[r].contacts.data(), n[1]);
    get_records(in, parts[r].created);
  }
  return parts;
}

// The checkpoint of the whole run on rank 0: this process's state with every process's bodies
// (ascending id) and warm starts (ascending key, each once).
std::optional<scene::SimulationState> gather_state(const Communicator& comm,
                                                   const scene::Simulation& sim) {
  scene::SimulationState state = sim.save();
  std::vector<std::byte> bytes;
  put_records(bytes, state.bodies);
  const std::uint64_t m = state.warm_keys.size();
  put(bytes, &m, 1);
  put(bytes, state.warm_keys.data(), m);
  for (const Vector3& lambda : state.warm_lambda) put(bytes, lambda.data(), 3);
  std::vector<std::vector<std::byte>> all;
  comm.gather(bytes, all, 0);
  if (comm.rank() != 0) return std::nullopt;
  state.bodies.clear();
  std::vector<std::pair<timestep::ContactKey, Vector3>> warm;
  for (const std::vector<std::byte>& part : all) {
    Reader in(part);
    get_records(in, state.bodies);
    const auto n = in.value<std::uint64_t>();
    std::vector<timestep::ContactKey> keys(n);
    in.get(keys.data(), n);
    for (std::size_t k = 0; k < n; ++k) {
      Vector3 lambda;
      in.get(lambda.data(), 3);
      warm.emplace_back(keys[k], lambda);
    }
  }
  std::sort(
      state.bodies.begin(), state.bodies.end(),
      [](const timestep::BodyRecord& a, const timestep::BodyRecord& b) { return a.id < b.id; });
  std::sort(warm.begin(), warm.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  // After a restart every process holds every warm start until its first step: keep one each.
  warm.erase(std::unique(warm.begin(), warm.end(),
                         [](const auto& a, const auto& b) { return a.first == b.first; }),
             warm.end());
  state.warm_keys.clear();
  state.warm_lambda.clear();
  for (const auto& [key, lambda] : warm) {
    state.warm_keys.push_back(key);
    state.warm_lambda.push_back(lambda);
  }
  return state;
}

// The skin of the parallel step: the scene's, or half its tolerance radius.
double skin_of(const timestep::StepSettings& s) {
  return s.skin > 0.0 ? s.skin : 0.5 * s.tolerance_radius;
}

double largest_radius(const scene::Scene& scene) {
  double r = 0.0;
  for (const scene::BodyGroup& g : scene.groups) r = std::max(r, scene::largest_bounding_radius(g));
  return r;
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
      grid_(box, grid_dims(comm.size(), box.sizes()), scene.domain.periodic),
      parallel_{largest_radius(scene), scene.parallel.average_every, scene.parallel.rebalance_every,
                scene.parallel.imbalance} {
  // A pair of bodies must not touch both directly and through a periodic boundary: the contact
  // keys do not tell the two contacts apart.
  const timestep::StepSettings& s = scene.settings;
  const double reach =
      2.0 * parallel_.max_radius + s.contact_tolerance * s.tolerance_radius + skin_of(s);
  const char* axes = "xyz";
  for (int d = 0; d < 3; ++d) {
    const double period = scene.domain.box.max[d] - scene.domain.box.min[d];
    if (scene.domain.periodic[static_cast<std::size_t>(d)] && !(period > 2.0 * reach)) {
      throw scene::SceneError(scene.file.string() + ": [simulation] periodic: the domain is " +
                              format_number(period) + " m along " + axes[d] +
                              ", expected more than twice the reach of a contact, " +
                              format_number(2.0 * reach) + " m (two largest bodies and margins)");
    }
  }
}

std::unique_ptr<scene::StepEngine> SceneDecomposition::engine(
    timestep::BodySystem& system, const timestep::StaticGeometry& statics,
    const timestep::MaterialTable& materials, const timestep::StepSettings& settings) const {
  timestep::StepSettings s = settings;
  s.skin = skin_of(s);
  auto engine =
      std::make_unique<ParallelStepper>(comm_, grid_, system, statics, materials, s, parallel_);
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
  io::RecordPart part;
  std::vector<timestep::BodyRecord> created;  // rank 0: gathered, not yet written
  const auto gather_created = [&](scene::Simulation& sim) {
    part.bodies.clear();
    part.contacts.clear();
    part.created.swap(sim.created());
    sim.created().clear();
    std::vector<io::RecordPart> parts = gather_parts(comm, part);
    for (io::RecordPart& p : parts) {
      created.insert(created.end(), p.created.begin(), p.created.end());
    }
  };
  const auto write_record = [&](scene::Simulation& sim) {
    io::collect_record(sim, scene.output.contacts, part);
    std::vector<io::RecordPart> parts = gather_parts(comm, part);
    agreed(comm, [&] {
      if (!root) return;
      parts.front().created.insert(parts.front().created.end(), created.begin(), created.end());
      created.clear();
      output->write_record(sim.stepper().time(), sim.stepper().steps(), parts);
    });
  };
  if (options.restart) {
    io::Checkpoint checkpoint;
    agreed(comm, [&] { checkpoint = io::read_checkpoint(*options.restart); });
    if (const std::string difference =
            io::scene_difference(checkpoint.scene_text, scene.text, scene.file);
        root && !difference.empty() && options.on_warning) {
      options.on_warning(difference);
    }
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
    agreed(comm, [&] {
      if (!root) return;
      output = exists[0] != std::byte{0}
                   ? std::make_unique<io::OutputFile>(
                         options.output, scene, checkpoint.output,
                         io::RunIdentity{checkpoint.scene_text, checkpoint.state.bodies})
                   : std::make_unique<io::OutputFile>(options.output, scene);
    });
  } else {
    agreed(comm, [&] {
      simulation = std::make_unique<scene::Simulation>(scene, nullptr, *decomposition);
    });
    agreed(comm, [&] {
      if (root) output = std::make_unique<io::OutputFile>(options.output, scene);
    });
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
    gather_created(sim);
    std::optional<scene::SimulationState> state = gather_state(comm, sim);
    agreed(comm, [&] {
      if (!root) return;
      output->flush(created);
      io::write_checkpoint(options.checkpoint,
                           io::Checkpoint{std::move(*state), output->position(), scene.text});
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
      // The other processes wait in the step's exchanges: only an abort ends them. Rank 0's
      // output holds every record before this step (each is counted once it is complete).
      abort_run(std::string("the run failed: ") + e.what(), 1);
    }
    result.step_seconds += seconds_since(t0);
    ++result.steps;
    std::uint64_t bodies[1] = {sim.system().owned_count()};
    comm.sum(bodies);
    if (root) output->add_step(report, bodies[0]);
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
  gather_created(sim);
  agreed(comm, [&] {
    if (root) output->close(created);
  });
  if (root && result.stop_file) io::remove_stop_file(options);
  std::vector<std::byte> records(sizeof(std::uint64_t));
  if (root) {
    const std::uint64_t n = output->position().records;
    std::memcpy(records.data(), &n, sizeof n);
  }
  comm.broadcast(records, 0);
  std::memcpy(&result.records, records.data(), sizeof result.records);
  result.seconds = seconds_since(start);
  return result;
}

}  // namespace grbd::parallel
