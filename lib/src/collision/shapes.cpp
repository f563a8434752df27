/// \file
/// \brief The kind of a shape and its name.

#include "grbd/collision/shapes.hpp"

#include <type_traits>

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

}  // namespace grbd::collision
