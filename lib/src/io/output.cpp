// The output of a run (chapter 7): HDF5 with an XDMF description beside it.

#include "grbd/io/output.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <numeric>
#include <sstream>
#include <type_traits>

#include "grbd/version.hpp"
#include "grbd/core/collectives.hpp"
#include "io/h5util.hpp"

namespace grbd::io {

namespace {

using h5::check;
using h5::Handle;

std::string record_name(std::uint64_t index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06llu", static_cast<unsigned long long>(index));
  return name;
}

std::string utc_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

std::string host_name() {
  char name[256] = {};
  if (gethostname(name, sizeof(name) - 1) != 0) return "unknown";
  return name;
}

// Writes `text` to `path` atomically (temporary file, then rename).
void write_file_atomically(const std::filesystem::path& path, const std::string& text) {
  const std::filesystem::path temporary = path.string() + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out << text;
    out.flush();
    if (!out) throw IoError(temporary.string() + ": cannot write the XDMF file");
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error)
    throw IoError(path.string() + ": cannot rename the XDMF file into place: " + error.message());
}

Handle open_dataset(hid_t location, const char* name, const std::string& file) {
  if (H5Lexists(location, name, H5P_DEFAULT) <= 0)
    h5::fail(file, std::string("dataset ") + name + " is missing");
  return check(H5Dopen2(location, name, H5P_DEFAULT), H5Dclose, file,
               std::string("cannot open dataset ") + name);
}

Handle open_group(hid_t location, const char* name, const std::string& file) {
  if (H5Lexists(location, name, H5P_DEFAULT) <= 0)
    h5::fail(file, std::string("group ") + name + " is missing");
  return check(H5Gopen2(location, name, H5P_DEFAULT), H5Gclose, file,
               std::string("cannot open group ") + name);
}

// Opens an output file, checking that it is one (IoError naming it when not).
Handle open_output(const std::filesystem::path& path, unsigned mode, hid_t access = H5P_DEFAULT) {
  const std::string file = path.string();
  h5::require_regular_file(path, "grbd output file");
  if (H5Fis_hdf5(file.c_str()) <= 0) h5::fail(file, "is not an HDF5 file");
  const hid_t id = H5Fopen(file.c_str(), mode, access);
  if (id < 0 && h5::locked_elsewhere(path)) {
    h5::fail(file,
             "is in use: a grbd run writes it, or another program has it open (HDF5's lock); read "
             "it once the run has ended, or stop the run (its stop file) and read what it wrote");
  }
  Handle handle = check(id, H5Fclose, file, "cannot open the file (it may be damaged)");
  if (H5Aexists(handle.get(), "format") <= 0 ||
      h5::read_string(handle.get(), "format", file) != "grbd output") {
    h5::fail(file, "is not a grbd output file (attribute format is not \"grbd output\")");
  }
  const std::uint64_t version = h5::read_uint(handle.get(), "format_version", file);
  if (version != kOutputFormatVersion) {
    h5::fail(file, "format_version " + std::to_string(version) + ", this grbd reads version " +
                       std::to_string(kOutputFormatVersion));
  }
  return handle;
}

// Every body of the checkpoint must have its row, the same constants, among the first `rows`
// rows of /bodies: else the output belongs to another run.
void check_bodies(hid_t root, const std::string& file, std::uint64_t rows,
                  std::span<const timestep::BodyRecord> bodies) {
  std::vector<timestep::PackedBody> packed;
  Handle type = h5::body_row_type();
  h5::read_array(root, "bodies", type.get(), -1, 0, packed, file);
  packed.resize(std::min<std::size_t>(packed.size(), rows));
  std::vector<timestep::BodyRecord> table;
  table.reserve(packed.size());
  for (std::size_t i = 0; i < packed.size(); ++i) {
    try {
      table.push_back(timestep::unpack(packed[i]));
    } catch (const InvalidArgument& e) {
      h5::fail(file, "dataset bodies, row " + std::to_string(i) + ": " + e.what());
    }
  }
  // Rows by id (an index, not the records themselves: moving the records' shape variants inside
  // std::sort trips GCC 12's -Wmaybe-uninitialized).
  std::vector<std::pair<std::uint64_t, std::size_t>> by_id(table.size());
  for (std::size_t i = 0; i < table.size(); ++i) by_id[i] = {table[i].id, i};
  std::sort(by_id.begin(), by_id.end());
  for (const timestep::BodyRecord& body : bodies) {
    const auto found = std::lower_bound(by_id.begin(), by_id.end(),
                                        std::pair<std::uint64_t, std::size_t>{body.id, 0});
    const auto it = found == by_id.end() ? table.end()
                                         : table.begin() + static_cast<std::ptrdiff_t>(found->second);
    if (it == table.end() || it->id != body.id || !timestep::same_constants(*it, body)) {
      h5::fail(file, "belongs to another run: the body with id " + std::to_string(body.id) +
                         " of the checkpoint is " +
                         (it == table.end() || it->id != body.id ? "not in its table /bodies"
                                                                 : "another body in /bodies") +
                         "; nothing was changed (continue into a new output with -o)");
    }
  }
}

// Rows of the n × 3 dataset `name` (IoError naming it when it has another shape).
std::uint64_t rows_of_three(hid_t location, const char* name, const std::string& file) {
  Handle dataset = open_dataset(location, name, file);
  Handle space = check(H5Dget_space(dataset.get()), H5Sclose, file,
                       std::string("cannot read the shape of ") + name);
  hsize_t dims[2] = {0, 0};
  if (H5Sget_simple_extent_ndims(space.get()) != 2 ||
      H5Sget_simple_extent_dims(space.get(), dims, nullptr) != 2 || dims[1] != 3) {
    h5::fail(file, std::string("dataset ") + name + ": expected n × 3 values");
  }
  return dims[0];
}

// Writes the group /static: the static objects and the surface of triangles that draws them.
StaticSurface write_static(hid_t root, const scene::Scene& scene, const std::string& file) {
  const StaticSurface surface = static_surface(scene);
  Handle group = check(H5Gcreate2(root, "static", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                       file, "cannot create group static");
  const hid_t g = group.get();
  std::vector<double> points;
  points.reserve(3 * surface.points.size());
  for (const Vector3& p : surface.points) points.insert(points.end(), {p.x(), p.y(), p.z()});
  h5::write_array(g, "points", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, surface.points.size(), 3,
                  points.data(), file);
  h5::write_array(g, "triangles", H5T_STD_U64LE, H5T_NATIVE_UINT64, surface.triangles.size(), 3,
                  surface.triangles.data(), file);
  h5::write_array(g, "object", H5T_STD_U32LE, H5T_NATIVE_UINT32, surface.object.size(), 0,
                  surface.object.data(), file);
  std::vector<const char*> names;
  std::vector<std::uint8_t> shape;
  std::vector<std::uint32_t> material;
  for (const scene::StaticSpec& s : scene.statics) {
    names.push_back(s.name.c_str());
    shape.push_back(static_cast<std::uint8_t>(s.shape.index()));
    const auto m = std::find(scene.materials.begin(), scene.materials.end(), s.material);
    material.push_back(static_cast<std::uint32_t>(m - scene.materials.begin()));
  }
  Handle type = h5::string_type(file);
  h5::write_array(g, "names", type.get(), type.get(), names.size(), 0, names.data(), file);
  h5::write_array(g, "shape", H5T_STD_U8LE, H5T_NATIVE_UINT8, shape.size(), 0, shape.data(), file);
  h5::write_array(g, "material", H5T_STD_U32LE, H5T_NATIVE_UINT32, material.size(), 0,
                  material.data(), file);
  h5::describe(g, "points", "m", "I", file);
  h5::describe(g, "triangles", "1", nullptr, file);
  h5::describe(g, "object", "1", nullptr, file);
  h5::describe(g, "shape", "1", nullptr, file);
  h5::describe(g, "material", "1", nullptr, file);
  h5::write_attribute(
      g, "units",
      std::string(
          "points: m (frame I); triangles: rows of points, outward "
          "(counter-clockwise); object: row of names; shape: 0 sphere, "
          "1 box, 2 capsule, 3 half-space, 4 mesh; material: row of "
          "/materials; bounds: the box (rows min, max) that cuts a half-space's plane into a "
          "polygon"),
      file);
  // Where the half-spaces were cut: rows min and max.
  const double bounds[6] = {surface.bounds.min.x(), surface.bounds.min.y(), surface.bounds.min.z(),
                            surface.bounds.max.x(), surface.bounds.max.y(), surface.bounds.max.z()};
  h5::write_array(g, "bounds", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, 3, bounds, file);
  h5::describe(g, "bounds", "m", "I", file);
  return surface;
}

}  // namespace

std::size_t first_different_line(std::string_view a, std::string_view b) {
  std::size_t line = 1;
  const std::size_t n = std::min(a.size(), b.size());
  for (std::size_t i = 0; i < n && a[i] == b[i]; ++i) line += a[i] == '\n' ? 1 : 0;
  return line;
}

Handle overlap_row_type();
void read_rows(hid_t table, hid_t type, std::uint64_t first, std::uint64_t n, void* out,
               const std::string& file);
void describe_overlaps(hid_t table, double unit, const std::string& file);

struct OutputFile::Impl {
  std::unique_ptr<h5::FileLock> lock;  // first: released after every handle is closed
  const Communicator* comm = nullptr;  // the processes that write the file together
  Handle transfer;                     // collective MPI-IO transfers with more than one process
  std::filesystem::path path;
  std::string file;
  bool float32 = false;
  Handle handle;
  Handle bodies;
  Handle steps;
  Handle records;
  Handle record_time;
  Handle record_step;
  Handle record_bodies;
  Handle record_contacts;  // with [output] contacts: the contacts of each record
  Handle record_overlaps;  // the overlaps' histogram of each record's last step (none: older files)
  Handle overlaps_type = overlap_row_type();
  timestep::OverlapHistogram last_overlaps;  // of the last step added
  bool contacts = false;
  Handle body_type = h5::body_row_type();
  Handle step_type = h5::step_row_type();
  std::vector<h5::StepRow> pending_steps;
  std::vector<timestep::PackedBody> packed_bodies;  // rows of /bodies being written
  // What the XDMF lists: time and body count of each complete record.
  std::vector<double> times;
  std::vector<std::uint64_t> counts;
  std::vector<std::uint64_t> contact_counts;  // with [output] contacts
  // The static geometry's surface (/static): vertices and triangles, 0 when there is none.
  std::uint64_t static_points = 0;
  std::uint64_t static_triangles = 0;
  // The XDMF file, open to append records over its footer, which starts at xdmf_footer.
  std::fstream xdmf;
  std::streamoff xdmf_footer = 0;
  bool root() const { return comm->rank() == 0; }
  // Every handle of the file, innermost first.
  void close_handles() {
    for (Handle* h : {&record_overlaps, &record_contacts, &record_bodies, &record_step, &record_time, &records,
                      &steps, &bodies}) {
      h->close();
    }
  }
  // Scratch of a record.
  std::vector<std::uint64_t> contact_ids, line_nodes;
  std::vector<double> point, normal, gap, lambda_N, lambda_T, line;
  std::vector<std::uint64_t> ids;
  std::vector<double> r, p, v, w, radius;
};

// A row of /records/overlaps: the counts of an OverlapHistogram.
Handle overlap_row_type() {
  const hsize_t bins = timestep::OverlapHistogram::kBins;
  return Handle(H5Tarray_create2(H5T_STD_U64LE, 1, &bins), H5Tclose);
}

// Reads rows [first, first + n) of the 1-D dataset `table` as `type` into `out`.
void read_rows(hid_t table, hid_t type, std::uint64_t first, std::uint64_t n, void* out,
               const std::string& file) {
  if (n == 0) return;
  Handle space = check(H5Dget_space(table), H5Sclose, file, "cannot read a dataset's shape");
  const hsize_t start = first, count = n;
  check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, &start, nullptr, &count, nullptr), file,
        "cannot select rows");
  Handle memory = check(H5Screate_simple(1, &count, nullptr), H5Sclose, file,
                        "cannot create a dataspace");
  check(H5Dread(table, type, memory.get(), space.get(), H5P_DEFAULT, out), file,
        "cannot read rows");
}

// What a reader needs to turn the counts into overlaps: the unit r and the bins' edges.
void describe_overlaps(hid_t table, double unit, const std::string& file) {
  using H = timestep::OverlapHistogram;
  h5::write_attribute(table, "unit", unit, file);
  h5::write_attribute(table, "bins_per_decade", std::uint64_t{H::kPerDecade}, file);
  h5::write_attribute(table, "decades", std::uint64_t{H::kDecades}, file);
  h5::write_attribute(
      table, "description",
      std::string("counts of the overlaps d = max(0, -g_N) of the contacts at the midpoint of "
                  "the record's last step (a fresh run's first record: none), in bins of d/unit "
                  "(unit: m, the smallest radius of the scene): bin 0 d/unit < 1e-8, bin b in "
                  "1 ... 20*decades: 10^(-8+(b-1)/20) <= d/unit < 10^(-8+b/20), the last bin "
                  "d/unit >= 1"),
      file);
}

std::filesystem::path OutputFile::xdmf_path(const std::filesystem::path& path) {
  std::filesystem::path xdmf = path;
  xdmf.replace_extension(".xmf");
  return xdmf;
}

OutputFile::OutputFile(const std::filesystem::path& path, const scene::Scene& scene,
                       const Communicator& comm)
    : OutputFile(path, comm, [&] { create(scene); }) {}

OutputFile::OutputFile(const std::filesystem::path& path, const scene::Scene& scene,
                       const OutputPosition& at, const RunIdentity& run, const Communicator& comm)
    : OutputFile(path, comm, [&] { reopen(scene, at, run); }) {}

OutputFile::OutputFile(const std::filesystem::path& path, const Communicator& comm,
                       const std::function<void()>& on_rank_0) {
  std::lock_guard lock(hdf5::mutex());
  hdf5::QuietErrors quiet;
  impl_.reset(new Impl);  // its compound types are HDF5 objects: made under the lock
  impl_->comm = &comm;
  impl_->path = path;
  impl_->file = path.string();
  agree(comm, [&] {
    if (comm.rank() == 0) on_rank_0();
  });
  share();
}

// [share output]
void OutputFile::share() {
  Impl& o = *impl_;
  const Communicator& comm = *o.comm;
  o.transfer = h5::shared_transfer(comm, o.file);
  if (comm.size() == 1) return;
  // Rank 0 has created or reopened the file alone (its checks, the XDMF); it closes it, keeping
  // its lock, and every process opens it for parallel writes.
  std::vector<std::byte> state(5 * sizeof(std::uint64_t));
  if (o.root()) {
    o.close_handles();
    const bool closed = o.handle.close();
    const std::uint64_t values[5] = {written_.records, written_.steps, written_.bodies,
                                     std::uint64_t{o.contacts} | std::uint64_t{closed} << 1,
                                     std::uint64_t{o.float32}};
    std::memcpy(state.data(), values, state.size());
  }
  comm.broadcast(state, 0);
  std::uint64_t values[5];
  std::memcpy(values, state.data(), state.size());
  written_ = {values[0], values[1], values[2]};
  o.contacts = (values[3] & 1) != 0;
  o.float32 = values[4] != 0;
  if ((values[3] & 2) == 0) throw IoError(o.file + ": cannot close the output file on rank 0");
  agree(comm, [&] {
    o.handle = check(H5Fopen(o.file.c_str(), H5F_ACC_RDWR, h5::shared_access(comm, o.file).get()),
                     H5Fclose, o.file, "cannot open the output file on every process");
    const hid_t root = o.handle.get();
    o.bodies = open_dataset(root, "bodies", o.file);
    o.steps = open_dataset(root, "steps", o.file);
    o.records = open_group(root, "records", o.file);
    o.record_time = open_dataset(o.records.get(), "time", o.file);
    o.record_step = open_dataset(o.records.get(), "step", o.file);
    o.record_bodies = open_dataset(o.records.get(), "bodies", o.file);
    if (o.contacts) o.record_contacts = open_dataset(o.records.get(), "contacts", o.file);
    if (H5Lexists(o.records.get(), "overlaps", H5P_DEFAULT) > 0) {  // none in earlier versions
      o.record_overlaps = open_dataset(o.records.get(), "overlaps", o.file);
    }
  });
}
// [share output]

void OutputFile::create(const scene::Scene& scene) {
  Impl& o = *impl_;
  const std::filesystem::path& path = o.path;
  o.float32 = scene.output.float32;
  // The lock before the truncation: a file that another run writes is refused untouched.
  o.lock = std::make_unique<h5::FileLock>(path, true);
  o.handle =
      check(H5Fcreate(o.file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, h5::locked_access(o.file).get()),
            H5Fclose, o.file, "cannot create the output file");
  const hid_t root = o.handle.get();
  h5::write_attribute(root, "format", std::string("grbd output"), o.file);
  h5::write_attribute(root, "format_version", kOutputFormatVersion, o.file);
  h5::write_attribute(root, "grbd_version", std::string(GRBD_VERSION), o.file);
  h5::write_attribute(root, "host", host_name(), o.file);
  h5::write_attribute(root, "date", utc_now(), o.file);
  h5::write_attribute(root, "scene_file", scene.file.string(), o.file);
  h5::write_attribute(root, "scene", scene.text, o.file);
  h5::write_attribute(root, "precision", std::string(o.float32 ? "float" : "double"), o.file);
  h5::write_attribute(root, "dt", scene.settings.dt, o.file);
  {
    Handle type = h5::string_type(o.file);
    std::vector<const char*> names;
    for (const std::string& m : scene.materials) names.push_back(m.c_str());
    h5::write_array(root, "materials", type.get(), type.get(), names.size(), 0, names.data(),
                    o.file);
  }
  o.bodies = h5::create_table(root, "bodies", h5::packed(o.body_type.get()).get(), 4096, o.file);
  o.steps = h5::create_table(root, "steps", h5::packed(o.step_type.get()).get(), 1024, o.file);
  o.records = check(H5Gcreate2(root, "records", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                    o.file, "cannot create group records");
  o.record_time = h5::create_table(o.records.get(), "time", H5T_IEEE_F64LE, 256, o.file);
  o.record_step = h5::create_table(o.records.get(), "step", H5T_STD_U64LE, 256, o.file);
  o.record_bodies = h5::create_table(o.records.get(), "bodies", H5T_STD_U64LE, 256, o.file);
  h5::write_attribute(o.records.get(), "count", std::uint64_t{0}, o.file);
  o.contacts = scene.output.contacts;
  h5::write_attribute(o.records.get(), "contacts", std::uint64_t{o.contacts ? 1u : 0u}, o.file);
  if (o.contacts) {
    o.record_contacts = h5::create_table(o.records.get(), "contacts", H5T_STD_U64LE, 256, o.file);
    h5::describe(o.records.get(), "contacts", "1", nullptr, o.file);
  }
  o.record_overlaps =
      h5::create_table(o.records.get(), "overlaps", o.overlaps_type.get(), 256, o.file);
  describe_overlaps(o.record_overlaps.get(), scene.settings.tolerance_radius, o.file);
  h5::describe(o.records.get(), "time", "s", nullptr, o.file);
  h5::describe(o.records.get(), "step", "1", nullptr, o.file);
  h5::describe(o.records.get(), "bodies", "1", nullptr, o.file);
  // A table's columns have their units in one attribute, column by column.
  h5::write_attribute(o.bodies.get(), "units",
                      std::string("id: 1; shape: 0 sphere, 1 box, 2 capsule; fixed: 0 or 1; "
                                  "material: row of /materials; radius: m; half_extents: m "
                                  "(frame K); half_length: m; mass: kg; K_Theta: kg m^2 "
                                  "(principal, frame K)"),
                      o.file);
  h5::write_attribute(o.steps.get(), "units",
                      std::string("step: 1; t: s; bodies, contacts, warm_started, iterations: 1; "
                                  "converged: 0 or 1; residual: natural map (chapter 5); "
                                  "kinetic_energy, potential_energy: J; max_penetration, mean_penetration, "
                                  "p99_penetration (the upper edge of its bin of /records/overlaps' "
                                  "scale, at most 12 % above): m; "
                                  "seconds_*: s of wall time"),
                      o.file);
  const StaticSurface surface = write_static(root, scene, o.file);
  o.static_points = surface.points.size();
  o.static_triangles = surface.triangles.size();
  check(H5Fflush(root, H5F_SCOPE_LOCAL), o.file, "cannot flush");
  write_xdmf();
}

void OutputFile::reopen(const scene::Scene& scene, const OutputPosition& at,
                        const RunIdentity& run) {
  Impl& o = *impl_;
  const std::filesystem::path& path = o.path;
  o.lock = std::make_unique<h5::FileLock>(path, false);
  o.handle = open_output(path, H5F_ACC_RDWR, h5::locked_access(o.file).get());
  const hid_t root = o.handle.get();
  // Nothing is cut back before the file is known to be the output of the run that continues.
  if (const std::string text = h5::read_string(root, "scene", o.file); text != run.scene_text) {
    h5::fail(o.file, "belongs to another run: its scene differs from the checkpoint's at line " +
                         std::to_string(first_different_line(text, run.scene_text)) +
                         "; nothing was changed (continue into a new output with -o)");
  }
  o.float32 = h5::read_string(root, "precision", o.file) == "float";
  if (o.float32 != scene.output.float32) {
    h5::fail(o.file, "was written in " + std::string(o.float32 ? "float" : "double") +
                         " precision, the scene asks for the other");
  }
  o.bodies = open_dataset(root, "bodies", o.file);
  o.steps = open_dataset(root, "steps", o.file);
  if (H5Lexists(root, "static", H5P_DEFAULT) > 0) {  // outputs of earlier versions have none
    Handle group = open_group(root, "static", o.file);
    o.static_points = rows_of_three(group.get(), "points", o.file);
    o.static_triangles = rows_of_three(group.get(), "triangles", o.file);
  }
  o.records = open_group(root, "records", o.file);
  o.record_time = open_dataset(o.records.get(), "time", o.file);
  o.record_step = open_dataset(o.records.get(), "step", o.file);
  o.record_bodies = open_dataset(o.records.get(), "bodies", o.file);
  o.contacts = H5Aexists(o.records.get(), "contacts") > 0 &&
               h5::read_uint(o.records.get(), "contacts", o.file) != 0;
  if (o.contacts != scene.output.contacts) {
    h5::fail(o.file, std::string("was written ") + (o.contacts ? "with" : "without") +
                         " the contacts of its records, the scene asks for the other ([output] "
                         "contacts)");
  }
  if (o.contacts) o.record_contacts = open_dataset(o.records.get(), "contacts", o.file);
  if (H5Lexists(o.records.get(), "overlaps", H5P_DEFAULT) > 0) {  // outputs of earlier versions
    o.record_overlaps = open_dataset(o.records.get(), "overlaps", o.file);
    if (h5::rows(o.record_overlaps.get(), o.file, "records/overlaps") < at.records) {
      h5::fail(o.file, "holds less than the checkpoint counts in records/overlaps: it is not "
                       "this run's output");
    }
    // The record after the checkpoint's (an extra last record at the checkpoint's step) is written
    // again before any step of this run: it keeps the histogram of the step it was taken after.
    if (at.steps > 0 &&
        h5::rows(o.record_overlaps.get(), o.file, "records/overlaps") > at.records &&
        h5::rows(o.record_step.get(), o.file, "records/step") > at.records) {
      std::uint64_t record_step = 0;
      h5::StepRow last{};
      Handle step_type = h5::step_row_type();
      read_rows(o.record_step.get(), H5T_NATIVE_UINT64, at.records, 1, &record_step, o.file);
      read_rows(o.steps.get(), step_type.get(), at.steps - 1, 1, &last, o.file);
      if (record_step == last.step) {
        read_rows(o.record_overlaps.get(), o.overlaps_type.get(), at.records, 1,
                  o.last_overlaps.counts().data(), o.file);
      }
    }
    h5::resize(o.record_overlaps.get(), at.records, o.file, "records/overlaps");
  }
  const std::uint64_t count = h5::read_uint(o.records.get(), "count", o.file);
  if (count < at.records || h5::rows(o.steps.get(), o.file, "steps") < at.steps ||
      h5::rows(o.bodies.get(), o.file, "bodies") < at.bodies ||
      h5::rows(o.record_time.get(), o.file, "records/time") < at.records) {
    h5::fail(o.file, "holds less than the checkpoint counts (" + std::to_string(at.records) +
                         " records, " + std::to_string(at.steps) + " steps, " +
                         std::to_string(at.bodies) + " bodies): it is not this run's output");
  }
  check_bodies(root, o.file, at.bodies, run.bodies);
  // Drop what follows the checkpoint: it is written again.
  for (std::uint64_t k = at.records;; ++k) {
    const std::string name = record_name(k);
    if (H5Lexists(o.records.get(), name.c_str(), H5P_DEFAULT) <= 0) break;
    check(H5Ldelete(o.records.get(), name.c_str(), H5P_DEFAULT), o.file,
          "cannot delete record " + name);
  }
  h5::write_attribute(o.records.get(), "count", at.records, o.file);
  h5::resize(o.record_time.get(), at.records, o.file, "records/time");
  h5::resize(o.record_step.get(), at.records, o.file, "records/step");
  h5::resize(o.record_bodies.get(), at.records, o.file, "records/bodies");
  if (o.contacts) {
    if (h5::rows(o.record_contacts.get(), o.file, "records/contacts") < at.records) {
      h5::fail(o.file,
               "holds less than the checkpoint counts in records/contacts: it is not "
               "this run's output");
    }
    h5::resize(o.record_contacts.get(), at.records, o.file, "records/contacts");
    h5::read_array(o.records.get(), "contacts", H5T_NATIVE_UINT64,
                   static_cast<std::int64_t>(at.records), 0, o.contact_counts, o.file);
  }
  h5::resize(o.steps.get(), at.steps, o.file, "steps");
  h5::resize(o.bodies.get(), at.bodies, o.file, "bodies");
  h5::read_array(o.records.get(), "time", H5T_NATIVE_DOUBLE, static_cast<std::int64_t>(at.records),
                 0, o.times, o.file);
  h5::read_array(o.records.get(), "bodies", H5T_NATIVE_UINT64,
                 static_cast<std::int64_t>(at.records), 0, o.counts, o.file);
  // Who continued the run, and when: the creation's host and date stay as they are.
  const std::uint64_t restarts =
      H5Aexists(root, "restarts") > 0 ? h5::read_uint(root, "restarts", o.file) : 0;
  h5::write_attribute(root, "restarts", restarts + 1, o.file);
  h5::write_attribute(root, "restart_host", host_name(), o.file);
  h5::write_attribute(root, "restart_date", utc_now(), o.file);
  check(H5Fflush(root, H5F_SCOPE_LOCAL), o.file, "cannot flush");
  written_ = at;
  write_xdmf();
}

OutputFile::~OutputFile() = default;

void OutputFile::Release::operator()(Impl* impl) const {
  std::lock_guard lock(hdf5::mutex());
  hdf5::QuietErrors quiet;
  delete impl;
}

void OutputFile::add_step(const timestep::StepReport& report, std::size_t bodies) {
  h5::StepRow row{};
  row.step = report.step;
  row.t = report.t;
  row.bodies = bodies;
  row.contacts = report.contacts;
  row.warm_started = report.warm_started;
  row.iterations = report.iterations;
  row.converged = report.converged ? 1 : 0;
  row.residual = report.residual;
  row.kinetic_energy = report.kinetic_energy;
  row.potential_energy = report.potential_energy;
  row.max_penetration = report.max_penetration;
  row.mean_penetration = report.mean_penetration;
  row.p99_penetration = report.p99_penetration;
  row.seconds_midpoint = report.seconds.midpoint;
  row.seconds_detection = report.seconds.detection;
  row.seconds_assembly = report.seconds.assembly;
  row.seconds_solve = report.seconds.solve;
  row.seconds_update = report.seconds.update;
  row.seconds_total = report.seconds.total;
  impl_->pending_steps.push_back(row);
  impl_->last_overlaps = report.overlaps;
}

void OutputFile::write_bodies(std::vector<timestep::BodyRecord>& created) {
  Impl& o = *impl_;
  // In the order of ids, which is the order of creation, whichever process created them.
  h5::pack_rows(created, o.packed_bodies);
  created.clear();
  auto& rows = o.packed_bodies;
  const grbd::collective::Block block = grbd::collective::sort_across(
      *o.comm, rows, [](const timestep::PackedBody& row) { return timestep::packed_id(row); });
  if (block.total == 0) return;
  h5::resize(o.bodies.get(), written_.bodies + block.total, o.file, "bodies");
  h5::write_at(o.bodies.get(), o.body_type.get(), written_.bodies + block.offset, rows.size(), 0,
               rows.data(), o.transfer.get(), o.file, "bodies");
  written_.bodies += block.total;
}

void OutputFile::write_steps() {
  Impl& o = *impl_;
  // Every process has added the same steps; rank 0's rows are written.
  const std::uint64_t n = o.pending_steps.size();
  if (n == 0) return;
  h5::resize(o.steps.get(), written_.steps + n, o.file, "steps");
  h5::write_at(o.steps.get(), o.step_type.get(), written_.steps, o.root() ? n : 0, 0,
               o.pending_steps.data(), o.transfer.get(), o.file, "steps");
  written_.steps += n;
  o.pending_steps.clear();
}

bool OutputFile::contacts() const { return impl_->contacts; }

void OutputFile::flush(scene::Simulation& simulation) { flush(simulation.created()); }

void OutputFile::flush(std::vector<timestep::BodyRecord>& created) {
  std::lock_guard lock(hdf5::mutex());
  hdf5::QuietErrors quiet;
  write_bodies(created);
  write_steps();
  check(H5Fflush(impl_->handle.get(), H5F_SCOPE_LOCAL), impl_->file, "cannot flush");
}

// [collect contacts]
void collect_record(scene::Simulation& simulation, bool contacts, RecordPart& part) {
  const timestep::BodySystem& system = simulation.system();
  const std::size_t n = system.owned_count();
  const auto ids = system.ids();
  const auto states = system.states();
  part.bodies.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    RecordBody& b = part.bodies[i];
    b.id = ids[i];
    for (int d = 0; d < 7; ++d) b.q[static_cast<std::size_t>(d)] = states[i].q[d];
    for (int d = 0; d < 6; ++d) b.u[static_cast<std::size_t>(d)] = states[i].u[d];
    b.radius = system.bounding_radii()[i];
  }
  part.created.swap(simulation.created());
  simulation.created().clear();
  part.contacts.clear();
  if (!contacts) return;
  const timestep::MoreauStepper& stepper = simulation.stepper();
  const auto keys = stepper.keys();
  const auto detected = stepper.contacts();
  const auto lambda = stepper.percussions();
  const auto& problem = stepper.problem().contacts;
  // The last step's contacts (none before the first step).
  const std::size_t m = stepper.steps() > 0 ? keys.size() : 0;
  part.contacts.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    const collision::ContactGeometry& g = detected[k].geometry;
    const contact::CompactContact& c = problem[k];
    const Vector3 t2 = c.n.cross(c.t1);
    const Vector3 tangential = lambda[k](1) * c.t1 + lambda[k](2) * t2;
    // A line from side a to side b: a body's centre at the midpoint (contact point minus lever
    // arm; a static object or fixed body has none, and its contact point stands in).
    const Vector3 end_a = g.I_r_a - c.r_a, end_b = g.I_r_b - c.r_b;
    RecordContact& row = part.contacts[k];
    row.key = keys[k];
    row.gap = g.g_N;
    row.lambda_N = lambda[k](0);
    for (int d = 0; d < 3; ++d) {
      const auto e = static_cast<std::size_t>(d);
      row.point[e] = 0.5 * (g.I_r_a(d) + g.I_r_b(d));
      row.normal[e] = c.n(d);
      row.lambda_T[e] = tangential(d);
      row.line[e] = end_a(d);
      row.line[3 + e] = end_b(d);
    }
  }
}
// [collect contacts]

void OutputFile::write_record(scene::Simulation& simulation) {
  RecordPart part;
  collect_record(simulation, impl_->contacts, part);
  write_record(simulation.stepper().time(), simulation.stepper().steps(), part);
}

// [write record]
void OutputFile::write_record(double t, std::uint64_t step, RecordPart& part) {
  std::lock_guard lock(hdf5::mutex());
  hdf5::QuietErrors quiet;
  Impl& o = *impl_;
  write_bodies(part.created);
  write_steps();
  // This process's block of the record: its rows of the global order by id.
  std::vector<RecordBody>& bodies = part.bodies;
  const grbd::collective::Block block =
      grbd::collective::sort_across(*o.comm, bodies, [](const RecordBody& b) { return b.id; });
  const std::size_t n = bodies.size();
  o.ids.resize(n);
  o.r.resize(3 * n);
  o.p.resize(4 * n);
  o.v.resize(3 * n);
  o.w.resize(3 * n);
  o.radius.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const RecordBody& b = bodies[k];
    o.ids[k] = b.id;
    for (std::size_t d = 0; d < 3; ++d) {
      o.r[3 * k + d] = b.q[d];
      o.v[3 * k + d] = b.u[d];
      o.w[3 * k + d] = b.u[3 + d];
    }
    for (std::size_t d = 0; d < 4; ++d) o.p[4 * k + d] = b.q[3 + d];
    o.radius[k] = b.radius;
  }

  const std::uint64_t index = written_.records;
  const std::string name = record_name(index);
  // A record of the same index may be left from a run killed while writing it.
  if (H5Lexists(o.records.get(), name.c_str(), H5P_DEFAULT) > 0) {
    check(H5Ldelete(o.records.get(), name.c_str(), H5P_DEFAULT), o.file,
          "cannot replace record " + name);
  }
  Handle group =
      check(H5Gcreate2(o.records.get(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
            H5Gclose, o.file, "cannot create record " + name);
  const hid_t real = o.float32 ? H5T_IEEE_F32LE : H5T_IEEE_F64LE;
  const hid_t g = group.get(), x = o.transfer.get();
  const std::uint64_t N = block.total, at = block.offset;
  h5::write_rows(g, "id", H5T_STD_U64LE, H5T_NATIVE_UINT64, N, 0, at, n, o.ids.data(), x, o.file);
  h5::write_rows(g, "I_r_S", real, H5T_NATIVE_DOUBLE, N, 3, at, n, o.r.data(), x, o.file);
  h5::write_rows(g, "p", real, H5T_NATIVE_DOUBLE, N, 4, at, n, o.p.data(), x, o.file);
  h5::write_rows(g, "I_v_S", real, H5T_NATIVE_DOUBLE, N, 3, at, n, o.v.data(), x, o.file);
  h5::write_rows(g, "K_omega", real, H5T_NATIVE_DOUBLE, N, 3, at, n, o.w.data(), x, o.file);
  h5::write_rows(g, "radius", real, H5T_NATIVE_DOUBLE, N, 0, at, n, o.radius.data(), x, o.file);
  // Units and frames: positions and velocities in the inertial frame I, the angular velocity in
  // the body frame K, p the unit quaternion that turns K-coordinates into I-coordinates.
  h5::describe(g, "id", "1", nullptr, o.file);
  h5::describe(g, "I_r_S", "m", "I", o.file);
  h5::describe(g, "p", "1", "K to I", o.file);
  h5::describe(g, "I_v_S", "m/s", "I", o.file);
  h5::describe(g, "K_omega", "rad/s", "K", o.file);
  h5::describe(g, "radius", "m", nullptr, o.file);
  h5::write_attribute(g, "time", t, o.file);
  h5::write_attribute(g, "step", step, o.file);
  std::uint64_t contacts = 0;
  if (o.contacts) contacts = write_contacts(g, part.contacts);
  group.close();
  // The tables may hold rows of a record that a killed run did not count: overwrite them. Rank 0
  // writes the row of this record.
  const std::uint64_t count = N;
  const auto set_row = [&](hid_t table, hid_t type, const void* value, const char* table_name) {
    h5::resize(table, index + 1, o.file, table_name);
    h5::write_at(table, type, index, o.root() ? 1 : 0, 0, value, x, o.file, table_name);
  };
  set_row(o.record_time.get(), H5T_NATIVE_DOUBLE, &t, "records/time");
  set_row(o.record_step.get(), H5T_NATIVE_UINT64, &step, "records/step");
  set_row(o.record_bodies.get(), H5T_NATIVE_UINT64, &count, "records/bodies");
  if (o.contacts)
    set_row(o.record_contacts.get(), H5T_NATIVE_UINT64, &contacts, "records/contacts");
  if (o.record_overlaps.valid()) {
    set_row(o.record_overlaps.get(), o.overlaps_type.get(), o.last_overlaps.counts().data(),
            "records/overlaps");
  }
  // Everything of the record on disk first, then the count that makes it part of the file.
  check(H5Fflush(o.handle.get(), H5F_SCOPE_LOCAL), o.file, "cannot flush");
  h5::write_attribute(o.records.get(), "count", index + 1, o.file);
  check(H5Fflush(o.handle.get(), H5F_SCOPE_LOCAL), o.file, "cannot flush");
  written_.records = index + 1;
  if (!o.root()) return;
  o.times.push_back(t);
  o.counts.push_back(count);
  if (o.contacts) o.contact_counts.push_back(contacts);
  append_xdmf();
}
// [write record]

// [write contacts]
std::uint64_t OutputFile::write_contacts(std::int64_t record,
                                         std::vector<RecordContact>& contacts) {
  static_assert(std::is_same_v<hid_t, std::int64_t>);
  Impl& o = *impl_;
  const grbd::collective::Block block =
      grbd::collective::sort_across(*o.comm, contacts, [](const RecordContact& c) { return c.key; });
  const std::size_t m = contacts.size();
  o.contact_ids.resize(2 * m);
  o.point.resize(3 * m);
  o.normal.resize(3 * m);
  o.gap.resize(m);
  o.lambda_N.resize(m);
  o.lambda_T.resize(3 * m);
  o.line.resize(6 * m);
  o.line_nodes.resize(2 * m);
  for (std::size_t j = 0; j < m; ++j) {
    const RecordContact& c = contacts[j];
    o.contact_ids[2 * j] = c.key.a;
    o.contact_ids[2 * j + 1] = c.key.b;
    o.gap[j] = c.gap;
    o.lambda_N[j] = c.lambda_N;
    std::copy(c.point.begin(), c.point.end(), o.point.begin() + static_cast<std::ptrdiff_t>(3 * j));
    std::copy(c.normal.begin(), c.normal.end(),
              o.normal.begin() + static_cast<std::ptrdiff_t>(3 * j));
    std::copy(c.lambda_T.begin(), c.lambda_T.end(),
              o.lambda_T.begin() + static_cast<std::ptrdiff_t>(3 * j));
    std::copy(c.line.begin(), c.line.end(), o.line.begin() + static_cast<std::ptrdiff_t>(6 * j));
    o.line_nodes[2 * j] = 2 * (block.offset + j);
    o.line_nodes[2 * j + 1] = 2 * (block.offset + j) + 1;
  }
  Handle group = check(H5Gcreate2(record, "contacts", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                       H5Gclose, o.file, "cannot create a record's contacts");
  const hid_t g = group.get();
  const hid_t real = o.float32 ? H5T_IEEE_F32LE : H5T_IEEE_F64LE;
  const hid_t x = o.transfer.get();
  const std::uint64_t M = block.total, at = block.offset;
  h5::write_rows(g, "ids", H5T_STD_U64LE, H5T_NATIVE_UINT64, M, 2, at, m, o.contact_ids.data(), x,
                 o.file);
  h5::write_rows(g, "point", real, H5T_NATIVE_DOUBLE, M, 3, at, m, o.point.data(), x, o.file);
  h5::write_rows(g, "normal", real, H5T_NATIVE_DOUBLE, M, 3, at, m, o.normal.data(), x, o.file);
  h5::write_rows(g, "gap", real, H5T_NATIVE_DOUBLE, M, 0, at, m, o.gap.data(), x, o.file);
  h5::write_rows(g, "lambda_N", real, H5T_NATIVE_DOUBLE, M, 0, at, m, o.lambda_N.data(), x, o.file);
  h5::write_rows(g, "lambda_T", real, H5T_NATIVE_DOUBLE, M, 3, at, m, o.lambda_T.data(), x, o.file);
  h5::write_rows(g, "line", real, H5T_NATIVE_DOUBLE, 2 * M, 3, 2 * at, 2 * m, o.line.data(), x,
                 o.file);
  h5::write_rows(g, "line_nodes", H5T_STD_U64LE, H5T_NATIVE_UINT64, M, 2, at, m,
                 o.line_nodes.data(), x, o.file);
  h5::describe(g, "ids", "1", nullptr, o.file);
  h5::describe(g, "point", "m", "I", o.file);
  h5::describe(g, "normal", "1", "I", o.file);
  h5::describe(g, "gap", "m", nullptr, o.file);
  h5::describe(g, "lambda_N", "N s", nullptr, o.file);
  h5::describe(g, "lambda_T", "N s", "I", o.file);
  h5::describe(g, "line", "m", "I", o.file);
  h5::describe(g, "line_nodes", "1", nullptr, o.file);
  return M;
}
// [write contacts]

void OutputFile::abandon() {
  Impl& o = *impl_;
  for (Handle* h : {&o.record_contacts, &o.record_bodies, &o.record_step, &o.record_time,
                    &o.records, &o.steps, &o.bodies, &o.handle}) {
    h->release();
  }
}

void OutputFile::close(scene::Simulation& simulation) { close(simulation.created()); }

void OutputFile::close(std::vector<timestep::BodyRecord>& created) {
  std::lock_guard lock(hdf5::mutex());
  hdf5::QuietErrors quiet;
  Impl& o = *impl_;
  write_bodies(created);
  write_steps();
  o.close_handles();
  if (!o.handle.close()) h5::fail(o.file, "cannot close the output file");
  o.lock.reset();  // closed: other readers and writers may have it
  if (!o.root()) return;
  o.xdmf.close();
  if (o.xdmf.fail()) throw IoError(xdmf_path(o.path).string() + ": cannot close the XDMF file");
}

namespace {

constexpr std::string_view kXdmfFooter = "  </Grid>\n </Domain>\n</Xdmf>\n";

// The XDMF grid of record k with n bodies at time t: points with their radius, velocity,
// angular velocity and id, all datasets of the record's HDF5 group. With contacts (m ≥ 0), the
// record is a spatial collection of the bodies' grid and, when m > 0, the grid of its contacts:
// a line per contact between the two sides, with its percussions and normal.
void write_xdmf_grid(std::ostream& x, const std::string& h5_name, bool float32, std::uint64_t k,
                     double t, std::uint64_t n, bool contacts, std::uint64_t m) {
  const char* precision = float32 ? "4" : "8";
  const std::string record = h5_name + ":/records/" + record_name(k) + "/";
  std::string base = record;
  auto item = [&](const std::string& dims, const char* type, const char* bytes,
                  const std::string& dataset) {
    x << "     <DataItem Dimensions=\"" << dims << "\" NumberType=\"" << type << "\" Precision=\""
      << bytes << "\" Format=\"HDF\">" << base << dataset << "</DataItem>\n";
  };
  auto attribute = [&](const char* name, const char* kind, const char* center,
                       const std::string& dims, const char* type, const char* bytes,
                       const std::string& dataset) {
    x << "    <Attribute Name=\"" << name << "\" AttributeType=\"" << kind << "\" Center=\""
      << center << "\">\n";
    item(dims, type, bytes, dataset);
    x << "    </Attribute>\n";
  };
  const std::string vector = std::to_string(n) + " 3";
  const std::string scalar = std::to_string(n);
  if (contacts) {
    x << "   <Grid Name=\"record " << record_name(k)
      << "\" GridType=\"Collection\" CollectionType=\"Spatial\">\n"
      << "    <Time Value=\"" << t << "\"/>\n"
      << "   <Grid Name=\"bodies\" GridType=\"Uniform\">\n";
  } else {
    x << "   <Grid Name=\"record " << record_name(k) << "\" GridType=\"Uniform\">\n"
      << "    <Time Value=\"" << t << "\"/>\n";
  }
  x << "    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << n
    << "\" NodesPerElement=\"1\"/>\n"
    << "    <Geometry GeometryType=\"XYZ\">\n";
  item(vector, "Float", precision, "I_r_S");
  x << "    </Geometry>\n";
  attribute("radius", "Scalar", "Node", scalar, "Float", precision, "radius");
  attribute("velocity", "Vector", "Node", vector, "Float", precision, "I_v_S");
  attribute("angular_velocity_K", "Vector", "Node", vector, "Float", precision, "K_omega");
  attribute("id", "Scalar", "Node", scalar, "UInt", "8", "id");
  x << "   </Grid>\n";
  if (!contacts) return;
  if (m > 0) {
    base = record + "contacts/";
    const std::string lines = std::to_string(m);
    x << "   <Grid Name=\"contacts\" GridType=\"Uniform\">\n"
      << "    <Topology TopologyType=\"Polyline\" NumberOfElements=\"" << m
      << "\" NodesPerElement=\"2\">\n";
    item(lines + " 2", "UInt", "8", "line_nodes");
    x << "    </Topology>\n"
      << "    <Geometry GeometryType=\"XYZ\">\n";
    item(std::to_string(2 * m) + " 3", "Float", precision, "line");
    x << "    </Geometry>\n";
    attribute("lambda_N", "Scalar", "Cell", lines, "Float", precision, "lambda_N");
    attribute("lambda_T", "Vector", "Cell", lines + " 3", "Float", precision, "lambda_T");
    attribute("normal", "Vector", "Cell", lines + " 3", "Float", precision, "normal");
    attribute("gap", "Scalar", "Cell", lines, "Float", precision, "gap");
    x << "   </Grid>\n";
  }
  x << "   </Grid>\n";
}

}  // namespace

void OutputFile::write_xdmf() {
  Impl& o = *impl_;
  const std::string h5_name = o.path.filename().string();
  std::ostringstream x;
  x.precision(17);
  x << "<?xml version=\"1.0\" ?>\n"
    << "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
    << "<Xdmf Version=\"2.0\">\n"
    << " <Domain>\n";
  if (o.static_triangles > 0) {  // the static geometry: one grid of triangles, for every time
    const std::string base = h5_name + ":/static/";
    x << "  <Grid Name=\"static\" GridType=\"Uniform\">\n"
      << "   <Topology TopologyType=\"Triangle\" NumberOfElements=\"" << o.static_triangles
      << "\">\n"
      << "    <DataItem Dimensions=\"" << o.static_triangles
      << " 3\" NumberType=\"UInt\" Precision=\"8\" Format=\"HDF\">" << base
      << "triangles</DataItem>\n"
      << "   </Topology>\n"
      << "   <Geometry GeometryType=\"XYZ\">\n"
      << "    <DataItem Dimensions=\"" << o.static_points
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << base
      << "points</DataItem>\n"
      << "   </Geometry>\n"
      << "   <Attribute Name=\"object\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
      << "    <DataItem Dimensions=\"" << o.static_triangles
      << "\" NumberType=\"UInt\" Precision=\"4\" Format=\"HDF\">" << base << "object</DataItem>\n"
      << "   </Attribute>\n"
      << "  </Grid>\n";
  }
  x << "  <Grid Name=\"bodies\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (std::size_t k = 0; k < o.times.size(); ++k) {
    if (o.counts[k] == 0) continue;  // ParaView cannot show an empty grid
    write_xdmf_grid(x, h5_name, o.float32, k, o.times[k], o.counts[k], o.contacts,
                    o.contacts ? o.contact_counts[k] : 0);
  }
  x << kXdmfFooter;
  const std::string text = x.str();
  const std::filesystem::path path = xdmf_path(o.path);
  o.xdmf.close();
  write_file_atomically(path, text);
  // Kept open to append the records that follow in place, over the footer.
  o.xdmf.open(path, std::ios::binary | std::ios::in | std::ios::out);
  if (!o.xdmf) throw IoError(path.string() + ": cannot open the XDMF file to append to it");
  o.xdmf_footer = static_cast<std::streamoff>(text.size() - kXdmfFooter.size());
}

void OutputFile::append_xdmf() {
  Impl& o = *impl_;
  const std::size_t k = o.times.size() - 1;
  if (o.counts[k] == 0) return;  // ParaView cannot show an empty grid
  std::ostringstream x;
  x.precision(17);
  write_xdmf_grid(x, o.path.filename().string(), o.float32, k, o.times[k], o.counts[k], o.contacts,
                  o.contacts ? o.contact_counts[k] : 0);
  x << kXdmfFooter;
  const std::string text = x.str();
  o.xdmf.seekp(o.xdmf_footer);
  o.xdmf.write(text.data(), static_cast<std::streamsize>(text.size()));
  o.xdmf.flush();
  if (!o.xdmf) throw IoError(xdmf_path(o.path).string() + ": cannot append to the XDMF file");
  o.xdmf_footer += static_cast<std::streamoff>(text.size() - kXdmfFooter.size());
}

Hdf5Cleanup::Hdf5Cleanup() {
  std::lock_guard lock(hdf5::mutex());
  H5dont_atexit();
}

Hdf5Cleanup::~Hdf5Cleanup() {
  std::lock_guard lock(hdf5::mutex());
  if (H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_FILE) == 0) H5close();
}

namespace {

// Every row of the /steps table of an open output file, as StepInfo. Under hdf5::mutex().
std::vector<StepInfo> step_infos(hid_t root, const std::string& file) {
  std::vector<h5::StepRow> rows;
  Handle step_type = h5::step_row_type();
  h5::read_array(root, "steps", step_type.get(), -1, 0, rows, file);
  std::vector<StepInfo> steps;
  steps.reserve(rows.size());
  for (const h5::StepRow& row : rows) {
    steps.push_back({row.step, row.t, row.bodies, row.contacts, row.iterations, row.converged != 0,
                     row.residual, row.max_penetration, row.mean_penetration,
                     row.p99_penetration, row.kinetic_energy, row.seconds_total});
  }
  return steps;
}

}  // namespace

OutputSummary read_summary(const std::filesystem::path& path) {
  std::lock_guard lock(hdf5::mutex());
  hdf5::QuietErrors quiet;
  const std::string file = path.string();
  Handle handle = open_output(path, H5F_ACC_RDONLY);
  const hid_t root = handle.get();
  OutputSummary s;
  s.scene_file = h5::read_string(root, "scene_file", file);
  s.grbd_version = h5::read_string(root, "grbd_version", file);
  s.date = h5::read_string(root, "date", file);
  s.host = h5::read_string(root, "host", file);
  s.precision = h5::read_string(root, "precision", file);
  Handle records = open_group(root, "records", file);
  s.records = h5::read_uint(records.get(), "count", file);
  {
    Handle bodies = open_dataset(root, "bodies", file);
    s.bodies = h5::rows(bodies.get(), file, "bodies");
  }
  const std::vector<StepInfo> steps = step_infos(root, file);
  s.steps = steps.size();
  RunAccuracy& a = s.accuracy;
  for (const StepInfo& row : steps) {
    a.add(row);
    s.max_contacts = std::max<std::uint64_t>(s.max_contacts, row.contacts);
    if (!row.converged) {
      s.non_converged_iterations = std::max<std::uint64_t>(
          s.non_converged_iterations, static_cast<std::uint64_t>(std::max(row.iterations, 0)));
    }
    s.seconds += row.seconds;
  }
  if (H5Lexists(records.get(), "overlaps", H5P_DEFAULT) > 0) {
    Handle table = open_dataset(records.get(), "overlaps", file);
    a.unit = h5::read_double(table.get(), "unit", file);
    constexpr int kBins = timestep::OverlapHistogram::kBins;
    const hsize_t n = s.records;
    if (h5::rows(table.get(), file, "records/overlaps") < n) {
      h5::fail(file, "records/overlaps holds fewer rows than records@count");
    }
    std::vector<std::uint64_t> counts(n * kBins);
    Handle type = overlap_row_type();
    read_rows(table.get(), type.get(), 0, n, counts.data(), file);
    for (std::size_t k = 0; k < counts.size(); ++k) a.overlaps.counts()[k % kBins] += counts[k];
    a.overlaps_at_records = true;
  }
  if (s.records > 0) {
    std::vector<double> times;
    std::vector<std::uint64_t> counts;
    const std::uint64_t n =
        h5::read_array(records.get(), "time", H5T_NATIVE_DOUBLE, -1, 0, times, file);
    h5::read_array(records.get(), "bodies", H5T_NATIVE_UINT64, static_cast<std::int64_t>(n), 0,
                   counts, file);
    if (n < s.records) h5::fail(file, "records/time holds fewer rows than records@count");
    s.t_first = times.front();
    s.t_last = times[s.records - 1];
    s.bodies_last = counts[s.records - 1];
  }
  return s;
}

void RunAccuracy::count(bool step_converged, int iterations, double residual,
                        std::uint64_t step_contacts, double mean, double largest) {
  ++steps;
  converged += step_converged ? 1 : 0;
  const auto n = static_cast<std::uint64_t>(std::max(iterations, 0));
  sweeps += n;
  max_sweeps = std::max(max_sweeps, n);
  max_residual = std::max(max_residual, residual);
  contacts += step_contacts;
  overlap_sum += mean * static_cast<double>(step_contacts);
  max_overlap = std::max(max_overlap, largest);
}

void RunAccuracy::add(const timestep::StepReport& report) {
  count(report.converged, report.iterations, report.residual, report.contacts,
        report.mean_penetration, report.max_penetration);
  overlaps.add(report.overlaps);
}

void RunAccuracy::add(const StepInfo& step) {
  count(step.converged, step.iterations, step.residual, step.contacts, step.mean_penetration,
        step.max_penetration);
}

double RunAccuracy::converged_percent() const {
  return steps > 0 ? 100.0 * static_cast<double>(converged) / static_cast<double>(steps) : 100.0;
}

double RunAccuracy::mean_sweeps() const {
  return steps > 0 ? static_cast<double>(sweeps) / static_cast<double>(steps) : 0.0;
}

double RunAccuracy::mean_overlap() const {
  return contacts > 0 ? overlap_sum / static_cast<double>(contacts) : 0.0;
}

std::string RunAccuracy::describe() const {
  const auto number = [](double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", x);
    return std::string(text);
  };
  std::string s = "solver: " + std::to_string(converged) + " of " + std::to_string(steps) +
                  " steps converged (" + number(converged_percent()) +
                  " %), sweeps a step: mean " + number(mean_sweeps()) +
                  ", largest " + std::to_string(max_sweeps) + "; largest residual at exit " +
                  number(max_residual) + "\n";
  const auto both = [&](double x) {
    return number(x) + " m" + (unit > 0.0 ? " (" + number(x / unit) + " r)" : std::string());
  };
  s += "overlaps: mean " + both(mean_overlap());
  if (overlaps.count() > 0 && unit > 0.0) {
    s += ", 99th percentile " + both(p99_overlap()) +
         (overlaps_at_records ? " (at the records)" : "");
  }
  s += ", largest " + both(max_overlap);
  if (unit > 0.0) s += "; r = " + number(unit) + " m, the smallest radius";
  return s + "\n";
}

std::vector<StepInfo> read_steps(const std::filesystem::path& path) {
  std::lock_guard lock(hdf5::mutex());
  hdf5::QuietErrors quiet;
  const std::string file = path.string();
  Handle handle = open_output(path, H5F_ACC_RDONLY);
  return step_infos(handle.get(), file);
}

namespace {

// Record `index` of an output file opened to read (IoError naming the file when it holds no such
// record): the file, its group records and the record's group, open together. Under
// hdf5::mutex().
struct OpenRecord {
  Handle file;     // the output file
  Handle records;  // its group records
  Handle group;    // the record's group
};

OpenRecord open_record(const std::filesystem::path& path, std::uint64_t index) {
  const std::string file = path.string();
  OpenRecord open{open_output(path, H5F_ACC_RDONLY), {}, {}};
  open.records = open_group(open.file.get(), "records", file);
  const std::uint64_t count = h5::read_uint(open.records.get(), "count", file);
  if (index >= count) {
    h5::fail(file, "record " + std::to_string(index) + " asked for, the file holds " +
                       std::to_string(count));
  }
  const std::string name = record_name(index);
  open.group = open_group(open.records.get(), name.c_str(), file);
  return open;
}

}  // namespace

Record read_record(const std::filesystem::path& path, std::uint64_t index) {
  std::lock_guard lock(hdf5::mutex());
  hdf5::QuietErrors quiet;
  const std::string file = path.string();
  const OpenRecord open = open_record(path, index);
  const Handle& group = open.group;
  Record record;
  record.t = h5::read_double(group.get(), "time", file);
  record.step = h5::read_uint(group.get(), "step", file);
  const std::uint64_t n =
      h5::read_array(group.get(), "id", H5T_NATIVE_UINT64, -1, 0, record.id, file);
  std::vector<double> r, p, v, w;
  const auto rows = static_cast<std::int64_t>(n);
  h5::read_array(group.get(), "I_r_S", H5T_NATIVE_DOUBLE, rows, 3, r, file);
  h5::read_array(group.get(), "p", H5T_NATIVE_DOUBLE, rows, 4, p, file);
  h5::read_array(group.get(), "I_v_S", H5T_NATIVE_DOUBLE, rows, 3, v, file);
  h5::read_array(group.get(), "K_omega", H5T_NATIVE_DOUBLE, rows, 3, w, file);
  h5::read_array(group.get(), "radius", H5T_NATIVE_DOUBLE, rows, 0, record.radius, file);
  record.states.resize(n);
  for (std::uint64_t k = 0; k < n; ++k) {
    body::State& x = record.states[k];
    for (int d = 0; d < 3; ++d) {
      x.q[d] = r[3 * k + d];
      x.u[d] = v[3 * k + d];
      x.u[3 + d] = w[3 * k + d];
    }
    for (int d = 0; d < 4; ++d) x.q[3 + d] = p[4 * k + d];
  }
  return record;
}

std::vector<RecordContact> read_contacts(const std::filesystem::path& path, std::uint64_t index) {
  std::lock_guard lock(hdf5::mutex());
  hdf5::QuietErrors quiet;
  const std::string file = path.string();
  const OpenRecord open = open_record(path, index);
  if (h5::read_uint(open.records.get(), "contacts", file) == 0) {
    h5::fail(file, "holds no contacts (written without [output] contacts = true)");
  }
  Handle contacts = open_group(open.group.get(), "contacts", file);
  const hid_t g = contacts.get();
  std::vector<std::uint64_t> ids;
  std::vector<double> point, normal, gap, lambda_N, lambda_T, line;
  const std::uint64_t m = h5::read_array(g, "ids", H5T_NATIVE_UINT64, -1, 2, ids, file);
  const auto rows = static_cast<std::int64_t>(m);
  h5::read_array(g, "point", H5T_NATIVE_DOUBLE, rows, 3, point, file);
  h5::read_array(g, "normal", H5T_NATIVE_DOUBLE, rows, 3, normal, file);
  h5::read_array(g, "gap", H5T_NATIVE_DOUBLE, rows, 0, gap, file);
  h5::read_array(g, "lambda_N", H5T_NATIVE_DOUBLE, rows, 0, lambda_N, file);
  h5::read_array(g, "lambda_T", H5T_NATIVE_DOUBLE, rows, 3, lambda_T, file);
  h5::read_array(g, "line", H5T_NATIVE_DOUBLE, 2 * rows, 3, line, file);
  std::vector<RecordContact> out(m);
  for (std::uint64_t j = 0; j < m; ++j) {
    RecordContact& c = out[j];
    c.key.a = ids[2 * j];
    c.key.b = ids[2 * j + 1];
    c.gap = gap[j];
    c.lambda_N = lambda_N[j];
    for (int d = 0; d < 3; ++d) {
      c.point[d] = point[3 * j + d];
      c.normal[d] = normal[3 * j + d];
      c.lambda_T[d] = lambda_T[3 * j + d];
    }
    for (int d = 0; d < 6; ++d) c.line[d] = line[6 * j + d];
  }
  return out;
}

}  // namespace grbd::io
