// Chapter 8 demo: how a chute is divided among four processes.
//
// The domain is a chute's flow region, 1 m long (x), 0.2 m wide (y) and 0.05 m deep (z). Four
// processes divide it either as grid_dims() chooses (the factorisation with the least interface
// area) or 2 × 2 × 1, what MPI_Dims_create(4, 3) gives without looking at the domain. For 4000
// random centres in the domain the demo finds each one's owner (owner_of) and the subdomains other
// than its owner's that it reaches with ρ = 1 cm (overlaps): there it must be a ghost. The share
// of centres that are ghosts somewhere is what each step's exchange carries.
//
// Output in the data directory: decomposition.csv (x, y, owner and ghost copies for both grids)
// and values.txt (key = value, read by the book): dims (n_x × n_y × n_z of grid_dims), area_slices,
// area_square (interface areas [m²]), ghost_percent_slices, ghost_percent_square (centres with a
// ghost copy somewhere [%]), copies_slices, copies_square (ghost copies per 100 centres).
//
// Usage: `ch08_decomposition <data directory>`.

#include <array>
#include <cstdio>
#include <random>
#include <string>

#include "grbd/parallel/decomposition.hpp"
#include "grbd_demo/demo.hpp"

namespace {

using grbd::Vector3;
using grbd::parallel::Box;
using grbd::parallel::CartesianGrid;

struct Layout {
  CartesianGrid grid;
  double area = 0.0;
  int ghosts = 0;  // centres with a copy somewhere
  int copies = 0;  // copies in all
};

double interface_area(const CartesianGrid& grid) {
  const Vector3 L = grid.domain().sizes();
  const auto& n = grid.dims();
  return (n[0] - 1) * L.y() * L.z() + (n[1] - 1) * L.x() * L.z() + (n[2] - 1) * L.x() * L.y();
}

void run(const std::string& dir) {
  const Box domain(Vector3(0.0, 0.0, 0.0), Vector3(1.0, 0.2, 0.05));
  const int processes = 4;
  const double reach = 0.01;
  const std::array<int, 3> dims = grbd::parallel::grid_dims(processes, domain.sizes());
  Layout layouts[2] = {{CartesianGrid(domain, dims)}, {CartesianGrid(domain, {2, 2, 1})}};
  for (Layout& l : layouts) l.area = interface_area(l.grid);

  grbd::demo::OutputFile csv(std::filesystem::path(dir) / "decomposition.csv",
                             "x_m,y_m,owner_slices,copies_slices,owner_square,copies_square");
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = 4000;
  for (int k = 0; k < n; ++k) {
    const Vector3 c = domain.min() + Vector3(u(rng), u(rng), u(rng)).cwiseProduct(domain.sizes());
    csv << c.x() << ',' << c.y();
    for (Layout& l : layouts) {
      const int owner = l.grid.owner_of(c);
      int copies = 0;
      for (int r = 0; r < l.grid.size(); ++r) {
        if (r != owner && grbd::parallel::overlaps(c, reach, l.grid.subdomain(r))) ++copies;
      }
      l.ghosts += copies > 0 ? 1 : 0;
      l.copies += copies;
      csv << ',' << owner << ',' << copies;
    }
    csv << '\n';
  }
  csv.finish();

  grbd::demo::OutputFile values(std::filesystem::path(dir) / "values.txt");
  char line[256];
  std::snprintf(line, sizeof line, "dims = %d × %d × %d\n", dims[0], dims[1], dims[2]);
  values << line;
  const char* names[2] = {"slices", "square"};
  for (int i = 0; i < 2; ++i) {
    std::snprintf(line, sizeof line, "area_%s = %.3g\nghost_percent_%s = %.1f\ncopies_%s = %.1f\n",
                  names[i], layouts[i].area, names[i], 100.0 * layouts[i].ghosts / n, names[i],
                  100.0 * layouts[i].copies / n);
    values << line;
  }
  values.finish();
  std::printf("ch08_decomposition: 4 processes on a 1 × 0.2 × 0.05 m chute, reach 1 cm: grid_dims "
              "%d × %d × %d, interfaces %.3g m², %.1f %% of the centres have ghost copies; "
              "2 × 2 × 1: %.3g m², %.1f %%\n",
              dims[0], dims[1], dims[2], layouts[0].area, 100.0 * layouts[0].ghosts / n,
              layouts[1].area, 100.0 * layouts[1].ghosts / n);
}

}  // namespace

int main(int argc, char** argv) {
  if (const auto exit_code = grbd::demo::check_arguments(
          argc, argv, "ch08_decomposition", {"<data directory>"},
          "writes decomposition.csv and values.txt into the existing directory")) {
    return *exit_code;
  }
  try {
    run(argv[1]);
  } catch (...) {
    return grbd::demo::report_exception("ch08_decomposition", "the exercises of chapter 8");
  }
  return 0;
}
