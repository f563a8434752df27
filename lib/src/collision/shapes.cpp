/// \file
/// \brief The kind of a shape and its name.

#include "grbd/collision/shapes.hpp"

#include <cmath>
#include <memory>
#include <string>
#include <type_traits>

#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"

namespace grbd::collision {

ShapeKind kind(const Shape& shape) {
  return std::visit(
      [](const auto& s) {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, Sphere>) {
          return ShapeKind::sphere;
        } else if constexpr (std::is_same_v<T, Box>) {
          return ShapeKind::box;
        } else if constexpr (std::is_same_v<T, Capsule>) {
          return ShapeKind::capsule;
        } else if constexpr (std::is_same_v<T, HalfSpace>) {
          return ShapeKind::half_space;
        } else {
          return ShapeKind::mesh;
        }
      },
      shape);
}

std::string_view kind_name(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::sphere:
      return "sphere";
    case ShapeKind::box:
      return "box";
    case ShapeKind::capsule:
      return "capsule";
    case ShapeKind::half_space:
      return "half-space";
    case ShapeKind::mesh:
      return "mesh";
  }
  return "unknown";
}

double bounding_radius(const Shape& shape) {
  if (const auto* sphere = std::get_if<Sphere>(&shape)) return sphere->radius;
  if (const auto* box = std::get_if<Box>(&shape)) return box->half_extents.norm();
  if (const auto* capsule = std::get_if<Capsule>(&shape)) {
    return capsule->radius + capsule->half_length;
  }
  return 0.0;
}

void normalize_and_check(Shape& shape, std::string_view where) {
  // The messages are built only on failure: a valid shape is checked without allocating.
  switch (kind(shape)) {
    case ShapeKind::sphere:
      require_positive_finite(where, "sphere radius", std::get<Sphere>(shape).radius);
      break;
    case ShapeKind::box: {
      const Vector3& h = std::get<Box>(shape).half_extents;
      for (int i = 0; i < 3; ++i) require_positive_finite(where, "box half extent", h[i]);
      break;
    }
    case ShapeKind::capsule: {
      const Capsule& capsule = std::get<Capsule>(shape);
      require_positive_finite(where, "capsule radius", capsule.radius);
      if (!(capsule.half_length >= 0.0 && std::isfinite(capsule.half_length))) {
        throw InvalidArgument(std::string(where) + ": expected a finite capsule half length ≥ 0, found " +
                              format_number(capsule.half_length));
      }
      break;
    }
    case ShapeKind::half_space: {
      HalfSpace& half_space = std::get<HalfSpace>(shape);
      const double norm = half_space.I_n.norm();
      if (!(norm > 0.0 && std::isfinite(norm) && std::isfinite(half_space.offset))) {
        throw InvalidArgument(std::string(where) +
                              ": expected a finite non-zero half-space normal and a "
                              "finite offset, found |I_n| = " +
                              format_number(norm) + ", offset " + format_number(half_space.offset));
      }
      // The same plane with a unit normal.
      half_space.I_n /= norm;
      half_space.offset /= norm;
      break;
    }
    case ShapeKind::mesh:
      if (!std::get<std::shared_ptr<const StaticMesh>>(shape)) {
        throw InvalidArgument(std::string(where) + ": expected a mesh, found a null pointer");
      }
      break;
  }
}

}  // namespace grbd::collision
