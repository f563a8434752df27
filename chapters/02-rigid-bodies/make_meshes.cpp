// Chapter 2 demo: the meshes of the chapter, generated (never downloaded) and written as
// Wavefront OBJ files with grbd::body::write_obj().
//
//   space_donut.obj  torus about z, centre-line radius R = 0.3 m, tube radius r = 0.1 m,
//                    96 × 48 segments (9216 faces); the body of ch02_space_donut
//   box.obj          box with half-extents (0.08, 0.04, 0.01) m, a phone-sized slab; the body of
//                    ch02_dzhanibekov (which builds the same box in memory)
//   tetrahedron.obj  the tetrahedron with vertices 0, 0.1 e_x, 0.1 e_y, 0.1 e_z [m]
//   icosphere.obj    sphere of radius 0.1 m, icosahedron subdivided 4 times (5120 faces)
//   cylinder.obj     cylinder about z, radius 0.05 m, height 0.2 m, 64 segments
//
// For every mesh the program compares the volume and the inertia tensor computed from the mesh by
// the divergence theorem (grbd::body::mass_properties, density 1000 kg/m³) with the closed form
// of the exact solid, and prints a one-line summary. The meshes of the box and the tetrahedron
// are the solids themselves, so their errors are round-off; the sphere, the torus and the
// cylinder are inscribed polyhedra, whose errors are discretisation errors of second order in the
// edge length. In the student build, where the mass properties may still be unimplemented
// exercises, the meshes are written all the same and the comparison is skipped.
//
// The comparison's numbers, which the chapter quotes, also go to `values.txt` in the output
// directory (key = value lines read by the book at build time: \demo{ch02_meshes/values.txt#KEY}
// in chapter.md, the build's output directory being figures/ch02_meshes): for every mesh, by the
// file's stem, <stem>.faces, <stem>.volume_error and <stem>.inertia_error (relative errors as TeX,
// the inertia tensor's in the Frobenius norm), and for the torus the two errors in per cent
// (space_donut.volume_error_percent, space_donut.inertia_error_percent).
//
// Usage: `ch02_make_meshes <output directory>` (the directory is created if needed).

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <string>
#include <system_error>
#include <vector>

#include "grbd/body/mass_properties.hpp"
#include "grbd/body/triangle_mesh.hpp"
#include "grbd/core/error.hpp"
#include "grbd/core/types.hpp"
#include "grbd_demo/demo.hpp"

namespace {

using grbd::Vector3;
namespace body = grbd::body;

constexpr double kDensity = 1000.0;  // kg/m³, only for the comparison with the closed forms

struct NamedMesh {
  std::string file;            // file name in the output directory
  std::string comment;         // first line of the OBJ file
  body::TriangleMesh mesh;     // the generated mesh
  body::MassProperties exact;  // closed form of the solid it approximates
};

std::vector<NamedMesh> chapter_meshes() {
  const double R = 0.3;  // torus: centre-line radius [m]
  const double r = 0.1;  // torus: tube radius [m]
  const Vector3 box_half_extents(0.08, 0.04, 0.01);
  const double edge = 0.1;  // tetrahedron: length of the three edges at the origin [m]
  const double sphere_radius = 0.1;
  const double cylinder_radius = 0.05;
  const double cylinder_height = 0.2;

  // The tetrahedron 0, a e_x, a e_y, a e_z by direct integration over the simplex:
  // V = a³/6, S = (a/4)(1, 1, 1), ∫x² dV = a⁵/60 and ∫xy dV = a⁵/120 about the origin, then
  // Θ_O = ρ (tr J I − J) and Steiner's theorem.
  body::MassProperties tetrahedron;
  tetrahedron.volume = edge * edge * edge / 6.0;
  tetrahedron.mass = kDensity * tetrahedron.volume;
  tetrahedron.M_r_S = Vector3::Constant(edge / 4.0);
  {
    const double a5 = std::pow(edge, 5);
    grbd::Matrix3 J = grbd::Matrix3::Constant(kDensity * a5 / 120.0);  // ρ ∫ x xᵀ dV about 0
    J.diagonal().setConstant(kDensity * a5 / 60.0);
    const grbd::Matrix3 Theta_O = J.trace() * grbd::Matrix3::Identity() - J;
    const Vector3& s = tetrahedron.M_r_S;
    tetrahedron.M_Theta_S =
        Theta_O - tetrahedron.mass * (s.dot(s) * grbd::Matrix3::Identity() - s * s.transpose());
  }

  return {
      {"space_donut.obj", "grbd chapter 2: space donut, torus R = 0.3 m, r = 0.1 m, 96 x 48",
       body::torus_mesh(R, r, 96, 48), body::torus_mass_properties(R, r, kDensity)},
      {"box.obj", "grbd chapter 2: box, half-extents 0.08 x 0.04 x 0.01 m",
       body::box_mesh(box_half_extents), body::box_mass_properties(box_half_extents, kDensity)},
      {"tetrahedron.obj", "grbd chapter 2: tetrahedron 0, 0.1 e_x, 0.1 e_y, 0.1 e_z",
       body::tetrahedron_mesh(Vector3::Zero(), edge * Vector3::UnitX(), edge * Vector3::UnitY(),
                              edge * Vector3::UnitZ()),
       tetrahedron},
      {"icosphere.obj", "grbd chapter 2: icosphere, radius 0.1 m, 4 subdivisions",
       body::icosphere_mesh(sphere_radius, 4),
       body::sphere_mass_properties(sphere_radius, kDensity)},
      {"cylinder.obj", "grbd chapter 2: cylinder, radius 0.05 m, height 0.2 m, 64 segments",
       body::cylinder_mesh(cylinder_radius, cylinder_height, 64),
       body::cylinder_mass_properties(cylinder_radius, cylinder_height, kDensity)},
  };
}

// x ≥ 0 as TeX with two significant digits ("1.4\cdot10^{-16}"), "0" for an exact zero.
std::string tex_error(double x) { return x > 0.0 ? grbd::demo::tex_power(x) : std::string("0"); }

// Relative errors of the mesh's volume and inertia tensor against the closed form.
struct Comparison {
  double volume;
  double inertia;
};

Comparison compare(const NamedMesh& m) {
  const body::MassProperties p = body::mass_properties(m.mesh, kDensity, m.file);
  return {std::abs(p.volume - m.exact.volume) / m.exact.volume,
          (p.M_Theta_S - m.exact.M_Theta_S).norm() / m.exact.M_Theta_S.norm()};
}

}  // namespace

int main(int argc, char** argv) {
  const auto print_usage = [](std::ostream& out) {
    out << "usage: ch02_make_meshes <output directory>\n"
           "  writes space_donut.obj, box.obj, tetrahedron.obj, icosphere.obj, cylinder.obj and "
           "values.txt\n";
  };
  if (grbd::demo::wants_help(argc, argv)) {
    print_usage(std::cout);
    return 0;
  }
  if (argc != 2) {
    print_usage(std::cerr);
    return 2;
  }
  const std::filesystem::path out_dir = argv[1];
  try {
    std::error_code error;
    std::filesystem::create_directories(out_dir, error);
    if (const auto reason = grbd::demo::not_a_directory(out_dir)) {
      std::cerr << "ch02_make_meshes: "
                << grbd::demo::directory_message("output directory", out_dir,
                                                 error ? error.message() : *reason)
                << '\n';
      return 2;
    }
    const std::vector<NamedMesh> meshes = chapter_meshes();
    for (const NamedMesh& m : meshes) {
      body::write_obj(m.mesh, out_dir / m.file, m.comment);
    }

    std::printf("ch02_make_meshes: wrote %zu meshes to %s;", meshes.size(),
                out_dir.string().c_str());
    try {
      grbd::demo::Values values;
      for (const NamedMesh& m : meshes) {
        const Comparison c = compare(m);
        std::printf(" %s: %td faces, rel. error V %.1e, Theta_S %.1e;", m.file.c_str(),
                    static_cast<std::ptrdiff_t>(m.mesh.F.rows()), c.volume, c.inertia);
        const std::string stem = std::filesystem::path(m.file).stem().string();
        values.set(stem + ".faces", "%td", static_cast<std::ptrdiff_t>(m.mesh.F.rows()));
        values.set(stem + ".volume_error", "%s", tex_error(c.volume).c_str());
        values.set(stem + ".inertia_error", "%s", tex_error(c.inertia).c_str());
        if (stem == "space_donut") {
          values.set(stem + ".volume_error_percent", "%.2f", 100.0 * c.volume);
          values.set(stem + ".inertia_error_percent", "%.2f", 100.0 * c.inertia);
        }
      }
      std::printf("\n");
      values.write(out_dir / "values.txt");
    } catch (const grbd::NotImplemented& e) {
      std::printf(" mass properties not compared (%s)\n", e.exercise().c_str());
    }
  } catch (...) {
    return grbd::demo::report_exception("ch02_make_meshes", "the exercises of chapters 1 and 2");
  }
  return 0;
}
