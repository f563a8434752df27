#pragma once
/// \file
/// \brief One body as a value (chapters 6–8): its identity, shape, inertia, material, flags and
/// state in one record, and the record as a fixed-length string of bytes — the row the output and
/// the checkpoint write, and the message in which chapter 8's processes hand bodies to each other.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "grbd/body/rigid_body.hpp"
#include "grbd/collision/shapes.hpp"

namespace grbd::timestep {

/// The stable identity of a body (or of a static object): never reused within a run, kept by
/// reordering, removal, restart and, in chapter 8, migration between MPI ranks.
using GlobalId = std::uint64_t;
/// The index of a material in a MaterialTable.
using MaterialId = std::uint32_t;

/// Global ids of static objects are tagged with this bit in contact keys, so that a body and a
/// static object never share an identity. Body ids must stay below it.
inline constexpr GlobalId kStaticTag = GlobalId{1} << 63;

/// Flags of a body, one byte per body.
enum BodyFlags : std::uint8_t {
  kDynamic = 1U << 0,  ///< moves under forces and contacts; without it the body is fixed (u = 0)
  kOwned =
      1U << 1,  ///< owned by this process (BodySystem rows below owned_count()); ghosts lack it
};

/// Everything that describes one body: what BodySystem::add() takes and BodySystem::record()
/// gives, what a scene's generators make, and what the output and a checkpoint store.
// [body record]
struct BodyRecord {
  GlobalId id = 0;  ///< stable identity, unique in the system, < kStaticTag
  /// The collision shape, centred at S with its axes along K: a sphere, a box or a capsule.
  collision::Shape shape = collision::Sphere{};
  body::RigidBody inertia;        ///< mass and principal moments (frame K is principal)
  MaterialId material = 0;        ///< row of the material table
  std::uint8_t flags = kDynamic;  ///< BodyFlags: kDynamic or none (fixed: infinite mass, u = 0)
  body::State state;              ///< q = (I_r_S, p) with |p| = 1, u = (I_v_S, K_omega)

  /// True unless the body is fixed.
  bool dynamic() const { return (flags & kDynamic) != 0; }
};
// [body record]

/// Length of a packed record [bytes].
inline constexpr std::size_t kPackedBodyBytes = 192;
/// Length of the constants at the start of a packed record (everything but the state) [bytes].
inline constexpr std::size_t kPackedConstantsBytes = 88;

/// Byte offsets of the fields of a packed record, native byte order. The constants form the row
/// of the output's and the checkpoint's table /bodies (HDF5 reads and writes packed records with a
/// compound type of these offsets); a sphere has radius, a box half_extents, a capsule radius and
/// half_length, the other fields zero, as are the bytes 10–11.
namespace packed {
inline constexpr std::size_t id = 0;             ///< std::uint64_t
inline constexpr std::size_t shape = 8;          ///< std::uint8_t: collision::ShapeKind 0–2
inline constexpr std::size_t fixed = 9;          ///< std::uint8_t: 1 fixed, 0 dynamic
inline constexpr std::size_t material = 12;      ///< std::uint32_t
inline constexpr std::size_t radius = 16;        ///< double [m]
inline constexpr std::size_t half_extents = 24;  ///< 3 doubles [m]
inline constexpr std::size_t half_length = 48;   ///< double [m]
inline constexpr std::size_t mass = 56;          ///< double [kg]
inline constexpr std::size_t K_Theta = 64;       ///< 3 doubles [kg m²]
inline constexpr std::size_t q = 88;             ///< 7 doubles
inline constexpr std::size_t u = 144;            ///< 6 doubles
}  // namespace packed

/// A packed record.
using PackedBody = std::array<std::byte, kPackedBodyBytes>;

/// The record as bytes. Throws InvalidArgument for a shape that is not a sphere, a box or a
/// capsule, or flags other than kDynamic (a body's other flags belong to where it is stored).
void pack(const BodyRecord& record, std::span<std::byte, kPackedBodyBytes> bytes);
/// The record of packed bytes: the exact inverse of pack(). Throws InvalidArgument for a shape
/// code other than 0–2 or a fixed byte other than 0 or 1 (bytes that pack() did not write); the
/// values themselves are checked where the record is used (BodySystem::add()).
BodyRecord unpack(std::span<const std::byte, kPackedBodyBytes> bytes);
/// The global id of packed bytes (what unpack() would give as `id`, without the rest).
GlobalId packed_id(std::span<const std::byte, kPackedBodyBytes> bytes);
/// True when two records describe the same body, state aside: every constant equal, bit for bit.
bool same_constants(const BodyRecord& a, const BodyRecord& b);

}  // namespace grbd::timestep
