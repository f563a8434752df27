/// \file
/// \brief The body record and its packed bytes.

#include "grbd/timestep/body_record.hpp"

#include <algorithm>
#include <cstring>
#include <string>

#include "grbd/core/error.hpp"

namespace grbd::timestep {

namespace {

template <class T>
void put(std::span<std::byte, kPackedBodyBytes> bytes, std::size_t offset, const T& value) {
  std::memcpy(bytes.data() + offset, &value, sizeof(T));
}

template <class T>
T get(std::span<const std::byte, kPackedBodyBytes> bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

void put_doubles(std::span<std::byte, kPackedBodyBytes> bytes, std::size_t offset, const double* x,
                 std::size_t n) {
  std::memcpy(bytes.data() + offset, x, n * sizeof(double));
}

void get_doubles(std::span<const std::byte, kPackedBodyBytes> bytes, std::size_t offset, double* x,
                 std::size_t n) {
  std::memcpy(x, bytes.data() + offset, n * sizeof(double));
}

}  // namespace

// [pack]
void pack(const BodyRecord& record, std::span<std::byte, kPackedBodyBytes> bytes) {
  const collision::ShapeKind kind = collision::kind(record.shape);
  if (kind != collision::ShapeKind::sphere && kind != collision::ShapeKind::box &&
      kind != collision::ShapeKind::capsule) {
    throw InvalidArgument("pack (body " + std::to_string(record.id) +
                          "): expected a sphere, a "
                          "box or a capsule, found a " +
                          std::string(collision::kind_name(kind)));
  }
  if ((record.flags & ~kDynamic) != 0) {
    throw InvalidArgument("pack (body " + std::to_string(record.id) +
                          "): expected the flags "
                          "kDynamic or none, found " +
                          std::to_string(record.flags));
  }
  std::fill(bytes.begin(), bytes.begin() + kPackedConstantsBytes, std::byte{0});
  put(bytes, packed::id, record.id);
  put(bytes, packed::shape, static_cast<std::uint8_t>(kind));
  put(bytes, packed::fixed, static_cast<std::uint8_t>(record.dynamic() ? 0 : 1));
  put(bytes, packed::material, record.material);
  if (const auto* sphere = std::get_if<collision::Sphere>(&record.shape)) {
    put(bytes, packed::radius, sphere->radius);
  } else if (const auto* box = std::get_if<collision::Box>(&record.shape)) {
    put_doubles(bytes, packed::half_extents, box->half_extents.data(), 3);
  } else {
    const auto& capsule = std::get<collision::Capsule>(record.shape);
    put(bytes, packed::radius, capsule.radius);
    put(bytes, packed::half_length, capsule.half_length);
  }
  put(bytes, packed::mass, record.inertia.m);
  put_doubles(bytes, packed::K_Theta, record.inertia.K_Theta.data(), 3);
  put_doubles(bytes, packed::q, record.state.q.data(), 7);
  put_doubles(bytes, packed::u, record.state.u.data(), 6);
}
// [pack]

GlobalId packed_id(std::span<const std::byte, kPackedBodyBytes> bytes) {
  return get<std::uint64_t>(bytes, packed::id);
}

BodyRecord unpack(std::span<const std::byte, kPackedBodyBytes> bytes) {
  BodyRecord record;
  record.id = get<std::uint64_t>(bytes, packed::id);
  const auto shape = get<std::uint8_t>(bytes, packed::shape);
  const auto fixed = get<std::uint8_t>(bytes, packed::fixed);
  if (shape > static_cast<std::uint8_t>(collision::ShapeKind::capsule) || fixed > 1) {
    throw InvalidArgument("unpack (body " + std::to_string(record.id) +
                          "): expected a shape "
                          "code 0–2 (sphere, box, capsule) and a fixed byte 0 or 1, found " +
                          std::to_string(shape) + " and " + std::to_string(fixed));
  }
  record.flags = fixed ? 0 : kDynamic;
  record.material = get<std::uint32_t>(bytes, packed::material);
  switch (static_cast<collision::ShapeKind>(shape)) {
    case collision::ShapeKind::sphere:
      record.shape = collision::Sphere{get<double>(bytes, packed::radius)};
      break;
    case collision::ShapeKind::box: {
      collision::Box box;
      get_doubles(bytes, packed::half_extents, box.half_extents.data(), 3);
      record.shape = box;
      break;
    }
    default:
      record.shape = collision::Capsule{get<double>(bytes, packed::radius),
                                        get<double>(bytes, packed::half_length)};
      break;
  }
  record.inertia.m = get<double>(bytes, packed::mass);
  get_doubles(bytes, packed::K_Theta, record.inertia.K_Theta.data(), 3);
  get_doubles(bytes, packed::q, record.state.q.data(), 7);
  get_doubles(bytes, packed::u, record.state.u.data(), 6);
  return record;
}

bool same_constants(const BodyRecord& a, const BodyRecord& b) {
  PackedBody x;
  PackedBody y;
  pack(a, x);
  pack(b, y);
  return std::memcmp(x.data(), y.data(), kPackedConstantsBytes) == 0;
}

}  // namespace grbd::timestep
