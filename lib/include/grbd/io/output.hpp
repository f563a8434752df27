#pragma once
/// \file
/// \brief The output of a run (chapter 7): one HDF5 file with the bodies' constants, a table of
/// every step and records of q and u, and an XDMF file beside it that ParaView opens directly.
///
/// Layout (every name is in the chapter's table):
/// - attributes of `/`: `format` ("grbd output"), `format_version`, `grbd_version`, `host`,
///   `date` (UTC, ISO 8601), `scene_file`, `scene` (the scene's text), `precision`, `dt`;
/// - `/materials`: the material names, a material's id is its index;
/// - `/bodies`: one row per body created (id, shape, radius, half extents, half length, mass,
///   principal moments, material, fixed);
/// - `/steps`: one row per step (time, contacts, iterations, residual, converged, energies,
///   largest penetration, bodies, stage timings);
/// - `/records/time`, `/records/step`, `/records/bodies`, and one group `/records/NNNNNN` per
///   record with `id`, `I_r_S`, `p`, `I_v_S`, `K_omega` and `radius`, rows in ascending global id;
///   the attribute `/records@count` is the number of complete records; with `[output] contacts`,
///   `/records/contacts` counts each record's contacts and its group `contacts` holds them
///   (`ids`, `point`, `normal`, `gap`, `lambda_N`, `lambda_T`, and `line`, `line_nodes` for the
///   XDMF's lines), rows sorted by contact key;
/// - `/static`: the static geometry as triangles (`points`, `triangles`, `object`) and the
///   static objects' `names`, `shape` and `material` (see StaticSurface).
///
/// After every record the file is flushed and `count` is written last, so that a run killed at
/// any moment leaves a file that opens and holds every record counted.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "grbd/core/agreement.hpp"
#include "grbd/core/communicator.hpp"
#include "grbd/core/error.hpp"
#include "grbd/scene/simulation.hpp"
#include "grbd/timestep/stepper.hpp"

namespace grbd::io {

/// An output or checkpoint file that cannot be written or read: the message names the file and
/// the dataset or attribute.
class IoError : public Error {
 public:
  using Error::Error;
};

/// A run's files that coincide (the output, its XDMF, the checkpoint, their temporary names, the
/// scene, its meshes, the restart checkpoint and the stop file must be different files), or a
/// file name with a NUL character: a bad command line (`grbd run` exits 2).
class FileConflict : public IoError {
 public:
  using IoError::IoError;
};

/// grbd::run_agreed() with the kinds of error that the phases of a run tell apart, because the kind
/// decides the command line's exit code: every process throws the FileConflict, IoError,
/// scene::SceneError, scene::StateError or InvalidArgument that the lowest failing rank met
/// (collective; at one process the work runs and its error propagates as thrown).
template <class Work>
void agree(const Communicator& comm, Work&& work) {
  grbd::run_agreed<FileConflict, IoError, scene::SceneError, scene::StateError, InvalidArgument>(
      comm, std::forward<Work>(work));
}

/// How much of an output file was written: rows of /records, /steps and /bodies. A checkpoint
/// keeps it, so that a restart can drop what was written after the checkpoint.
struct OutputPosition {
  std::uint64_t records = 0;  ///< complete records
  std::uint64_t steps = 0;    ///< rows of /steps
  std::uint64_t bodies = 0;   ///< rows of /bodies
};

/// The format version written to and required from output files.
inline constexpr std::uint64_t kOutputFormatVersion = 2;

/// What identifies the run a restart continues: the output it reopens must be that run's.
struct RunIdentity {
  std::string scene_text;                        ///< the scene the run was started from
  std::span<const timestep::BodyRecord> bodies;  ///< the bodies at the checkpoint
};

/// The static geometry of a scene as one surface of triangles in frame I, which the output keeps
/// (group `/static`) so that ParaView shows the walls, floors and meshes among the bodies.
/// Spheres, boxes and capsules are tessellated (an icosphere of 320 faces, 12 faces, 24
/// segments around with 6 rings per hemisphere), meshes are taken as they are, and a half-space,
/// being infinite, is drawn as the polygon in which its plane cuts `bounds`: the outlet's box
/// when the scene has one, else the box of every body group's region or positions and of the
/// finite static objects, enlarged by 5 % of its largest side (at least two body sizes); each
/// plane is cut further by the other half-spaces, so that the planes draw the boundary of the
/// free space (a silo's floor between its walls).
struct StaticSurface {
  std::vector<Vector3> points;                          ///< vertices [m], frame I
  std::vector<std::array<std::uint64_t, 3>> triangles;  ///< rows of points, outward faces
  std::vector<std::uint32_t> object;                    ///< per triangle: index in scene.statics
  scene::Region bounds;                                 ///< where half-spaces were cut [m]
};

/// The surface of `scene.statics` (see StaticSurface).
StaticSurface static_surface(const scene::Scene& scene);

/// The line (1, 2, …) on which two texts first differ.
std::size_t first_different_line(std::string_view a, std::string_view b);

/// One body of a record: its global id, q, u and bounding radius (120 bytes, as a process of a
/// parallel run sends it to the one that writes).
struct RecordBody {
  std::uint64_t id = 0;       ///< global id
  std::array<double, 7> q{};  ///< I_r_S [m], p (K to I)
  std::array<double, 6> u{};  ///< I_v_S [m/s], K_omega [rad/s]
  double radius = 0.0;        ///< bounding radius [m]
};

/// One contact of a record (with [output] contacts): its key, the geometry and the percussions as
/// the group `contacts` of a record holds them.
struct RecordContact {
  timestep::ContactKey key;          ///< the contact's key: ids of sides a and b, features
  std::array<double, 3> point{};     ///< midpoint of the two closest points [m], frame I
  std::array<double, 3> normal{};    ///< from b towards a, frame I
  double gap = 0.0;                  ///< g_N [m]
  double lambda_N = 0.0;             ///< normal percussion [N s]
  std::array<double, 3> lambda_T{};  ///< tangential percussion [N s], frame I
  std::array<double, 6> line{};      ///< from side a's centre to side b's [m], frame I
};

/// What one process contributes to a record: its own bodies and the contacts it solved, in any
/// order (the file holds them sorted by id and by key), and the bodies created since the last
/// write (for /bodies).
struct RecordPart {
  std::vector<RecordBody> bodies;             ///< the bodies it owns
  std::vector<RecordContact> contacts;        ///< the last step's contacts it solved
  std::vector<timestep::BodyRecord> created;  ///< created since the last write
};

/// The part of a record that a simulation holds (its owned bodies; the contacts of its last step
/// when `contacts`), taking the bodies it created since the last call (Simulation::created()).
void collect_record(scene::Simulation& simulation, bool contacts, RecordPart& part);

/// The output file of a run. Steps are buffered and written with each record (or flush()).
/// While it is open, the file is locked (flock, as HDF5 does): a second OutputFile of the same
/// file, in this process or another, is refused before anything is changed.
///
/// The processes of a communicator write one file together (chapter 8): rank 0 creates or
/// reopens it alone (every check, the XDMF file, the lock), then every process opens it with
/// parallel HDF5 (MPI-IO), and each record is written collectively, each process writing its
/// block of rows of the global order by id (and by key for contacts). Every call is then
/// collective; an error is thrown on every process. The file is the one a single process writes.
class OutputFile {
 public:
  /// Creates `path` (replacing a file of that name, once it holds the lock) and the XDMF file
  /// beside it (`.xmf`). Throws IoError, having changed nothing, when another process holds
  /// the file.
  OutputFile(const std::filesystem::path& path, const scene::Scene& scene,
             const Communicator& comm = self_communicator());
  /// Reopens the output of an earlier run for a restart: keeps what `at` counts and drops the
  /// rest (records, steps and bodies written after the checkpoint). Throws IoError, having
  /// changed nothing, when the file is not a grbd output, holds less than `at`, or belongs to
  /// another run (its scene text is not `run.scene_text`, or a body of `run.bodies` is not in its
  /// table with the same constants).
  OutputFile(const std::filesystem::path& path, const scene::Scene& scene, const OutputPosition& at,
             const RunIdentity& run, const Communicator& comm = self_communicator());
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  /// Buffers the row of one step (every process adds the same steps; rank 0's rows, with its
  /// timings, are written).
  void add_step(const timestep::StepReport& report, std::size_t bodies);
  /// Writes the bodies created since the last call, the buffered steps and a record of every
  /// body's q and u (rows sorted by id); flushes, then counts the record; rewrites the XDMF.
  void write_record(scene::Simulation& simulation);
  /// The same from this process's part (collective: every process gives its own): the record of
  /// time t after `step` steps holds the bodies of every part sorted by id, their contacts sorted
  /// by key; /bodies gets their created bodies sorted by id. The part is used up.
  void write_record(double t, std::uint64_t step, RecordPart& part);
  /// Writes the bodies created and the buffered steps, and flushes (before a checkpoint).
  void flush(scene::Simulation& simulation);
  /// The same with the bodies this process created (collective; sorted by id over every process,
  /// and used up).
  void flush(std::vector<timestep::BodyRecord>& created);
  /// Whether this file keeps the contacts of each record ([output] contacts).
  bool contacts() const;
  /// What has been written (after flush(): everything so far).
  OutputPosition position() const { return written_; }
  /// Flushes, closes and releases the lock; throws IoError if HDF5 cannot. The destructor closes
  /// silently.
  void close(scene::Simulation& simulation);
  /// The same with the bodies created (as flush()).
  void close(std::vector<timestep::BodyRecord>& created);
  /// Leaves the file as its last flush made it, without closing it: after a write that failed on
  /// some process of a parallel run, the processes can no longer close it together (HDF5's
  /// collective close would wait for ever or crash). The file holds every record counted; the
  /// program must then end without finalizing MPI (io::AbandonedFiles).
  void abandon();
  /// The XDMF file written beside `path`.
  static std::filesystem::path xdmf_path(const std::filesystem::path& path);

 private:
  struct Impl;
  // Runs `on_rank_0` (create or reopen) on rank 0, agreed, then share().
  OutputFile(const std::filesystem::path& path, const Communicator& comm,
             const std::function<void()>& on_rank_0);
  // What the constructors do on rank 0 alone, and the opening by every process that follows.
  void create(const scene::Scene& scene);
  void reopen(const scene::Scene& scene, const OutputPosition& at, const RunIdentity& run);
  void share();
  void write_bodies(std::vector<timestep::BodyRecord>& created);
  // The group `contacts` of a record (with [output] contacts), sorted by key; returns how many
  // contacts every process wrote.
  std::uint64_t write_contacts(std::int64_t record, std::vector<RecordContact>& contacts);
  void write_steps();
  // The XDMF is written whole (atomically) when the file is created or reopened, and each record
  // is appended in place over its closing tags: O(1) per record, not O(records).
  void write_xdmf();
  void append_xdmf();
  // Deletes the HDF5 handles of Impl under grbd's HDF5 lock.
  struct Release {
    void operator()(Impl* impl) const;
  };
  std::unique_ptr<Impl, Release> impl_;
  OutputPosition written_;
};

/// HDF5's clean-up at exit, taken over for a program's main(): construct one first thing in
/// main(). HDF5 closes every file still open when the program exits; a file whose close failed (a
/// write that found the disk full) is still on its list, and closing it again there crashes
/// HDF5 1.10 (SIGSEGV in H5F__close_cb). With this object HDF5 installs no exit handler, and the
/// destructor shuts it down only when no file is left open — which then only one HDF5 cannot
/// close can be, left to the operating system.
class Hdf5Cleanup {
 public:
  Hdf5Cleanup();
  ~Hdf5Cleanup();
  Hdf5Cleanup(const Hdf5Cleanup&) = delete;
  Hdf5Cleanup& operator=(const Hdf5Cleanup&) = delete;
};

struct StepInfo;

/// How accurately the steps of a run were solved and how far its contacts overlap (chapter 6,
/// "Accuracy of a step"): what `grbd run` prints at its end, `grbd info` reads back from an output
/// and every study table carries beside its results.
struct RunAccuracy {
  std::uint64_t steps = 0;         ///< steps counted
  std::uint64_t converged = 0;     ///< of which the solver met its tolerance
  std::uint64_t sweeps = 0;        ///< solver iterations over the steps
  std::uint64_t max_sweeps = 0;    ///< the most of one step
  double max_residual = 0.0;       ///< the largest residual a step's solve stopped at
  std::uint64_t contacts = 0;      ///< contacts over the steps
  double overlap_sum = 0.0;        ///< Σ max(0, −g_N) over those contacts [m]
  double max_overlap = 0.0;        ///< the largest [m]
  /// The distribution of the overlaps: of every contact of every step (`grbd run`), or of the
  /// records' last steps (read from an output's /records/overlaps)
  timestep::OverlapHistogram overlaps;
  bool overlaps_at_records = false;  ///< where `overlaps` comes from
  double unit = 0.0;                 ///< the unit r of `overlaps`, the smallest radius [m]

  /// Counts one step, its overlaps' distribution too.
  void add(const timestep::StepReport& report);
  /// Counts one row of an output's /steps (which keeps no distribution).
  void add(const StepInfo& step);
  /// The share of the steps whose solve met its tolerance [%] (100 without steps).
  double converged_percent() const;
  /// The sweeps a step, the mean (0 without steps).
  double mean_sweeps() const;
  /// The mean overlap over the contacts [m] (0 without contacts).
  double mean_overlap() const;
  /// The 99th percentile of the overlaps [m] (the upper edge of its bin, ≤ 12 % above).
  double p99_overlap() const { return overlaps.quantile(0.99) * unit; }
  /// Two lines: the share of steps converged, sweeps (mean, largest) and the largest residual;
  /// the overlaps' mean, 99th percentile and largest in metres and in units of r.
  std::string describe() const;

 private:
  void count(bool step_converged, int iterations, double residual, std::uint64_t step_contacts,
             double mean, double largest);
};

/// What `grbd info` says about an output file.
struct OutputSummary {
  std::string scene_file;                      ///< attribute scene_file
  std::string grbd_version;                    ///< attribute grbd_version
  std::string date;                            ///< attribute date
  std::string host;                            ///< attribute host
  std::string precision;                       ///< "double" or "float"
  std::uint64_t bodies = 0;                    ///< rows of /bodies
  std::uint64_t steps = 0;                     ///< rows of /steps
  std::uint64_t records = 0;                   ///< complete records
  double t_first = 0.0;                        ///< time of the first record [s]
  double t_last = 0.0;                         ///< time of the last record [s]
  std::uint64_t bodies_last = 0;               ///< bodies in the last record
  std::uint64_t max_contacts = 0;              ///< over the steps
  /// The iterations the steps that did not converge stopped at: the cap (0 if all converged)
  std::uint64_t non_converged_iterations = 0;
  double seconds = 0.0;                        ///< wall time of the steps [s]
  /// Convergence, sweeps and overlaps of the steps; the overlaps' distribution of the records
  RunAccuracy accuracy;
};

/// Reads the summary of an output file (IoError naming the file and dataset when it is not one).
OutputSummary read_summary(const std::filesystem::path& path);

/// One step of an output file's /steps table, as an analysis of the run reads it.
struct StepInfo {
  std::uint64_t step = 0;        ///< the step's number
  double t = 0.0;                ///< the time at its end [s]
  std::uint64_t bodies = 0;      ///< bodies in the system
  std::uint64_t contacts = 0;    ///< contacts solved
  std::int32_t iterations = 0;   ///< sweeps of the solver
  bool converged = false;        ///< whether it reached its tolerance
  double residual = 0.0;         ///< the solver's last residual
  double max_penetration = 0.0;  ///< max(0, −g_N) over the contacts at the midpoint [m]
  double mean_penetration = 0.0;  ///< its mean over the contacts [m] (0 without contacts)
  double p99_penetration = 0.0;   ///< its 99th percentile (bin's upper edge) [m]
  double kinetic_energy = 0.0;   ///< of the bodies at the end of the step [J]
  double seconds = 0.0;          ///< wall time of the step [s]
};

/// Reads every step of an output file (IoError naming the file when it is not one).
std::vector<StepInfo> read_steps(const std::filesystem::path& path);

/// One record read back: the global ids and the states, rows in ascending id.
struct Record {
  double t = 0.0;                   ///< time [s]
  std::uint64_t step = 0;           ///< step count
  std::vector<std::uint64_t> id;    ///< global ids
  std::vector<body::State> states;  ///< q and u (converted to double)
  std::vector<double> radius;       ///< bounding radius of each body [m]
};

/// Reads record `index` (< records) of an output file.
Record read_record(const std::filesystem::path& path, std::uint64_t index);

/// Reads the contacts of record `index` of an output file written with [output] contacts (IoError
/// naming the file otherwise): the file keeps of a contact's key the ids of sides a and b, so the
/// features and the image of the keys read back are 0.
std::vector<RecordContact> read_contacts(const std::filesystem::path& path, std::uint64_t index);

}  // namespace grbd::io
