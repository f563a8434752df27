#pragma once
/// \file
/// \brief Quaternions ℍ: the algebra, the 2 × 2 complex representation, and the left and right
/// multiplication matrices φ_L and φ_R (chapter 1).

#include <Eigen/Core>

#include "grbd/core/types.hpp"

namespace grbd::kinematics {

/// A quaternion P = p0 + p1 i + p2 j + p3 k, stored by its coordinates
/// K(P) = (p0, p_r) = (p0, p1, p2, p3) ∈ ℝ⁴, **scalar first** (unlike Eigen::Quaternion).
///
/// The default-constructed quaternion is the identity 1 = (1, 0, 0, 0), the orientation of a
/// body frame K that coincides with the inertial frame I.
class Quaternion {
 public:
  /// The identity (1, 0, 0, 0).
  Quaternion() : K_(1.0, 0.0, 0.0, 0.0) {}
  /// P = p0 + p1 i + p2 j + p3 k.
  Quaternion(double p0, double p1, double p2, double p3) : K_(p0, p1, p2, p3) {}
  /// P = (p0, p_r) from its scalar and vector parts.
  Quaternion(double p0, const Vector3& p_r) : K_(p0, p_r.x(), p_r.y(), p_r.z()) {}
  /// P from its coordinates K(P) = (p0, p1, p2, p3).
  explicit Quaternion(const Vector4& K) : K_(K) {}

  /// The identity quaternion 1 = (1, 0, 0, 0).
  static Quaternion identity() { return {}; }
  /// The pure quaternion (0, x) that represents a vector x ∈ E³ (x ∈ ℝ³, any frame).
  static Quaternion pure(const Vector3& x) { return {0.0, x}; }

  /// The coordinates K(P) = (p0, p1, p2, p3), 4 × 1.
  const Vector4& coeffs() const { return K_; }
  /// The scalar part p0.
  double p0() const { return K_[0]; }
  /// The vector part p_r = (p1, p2, p3), 3 × 1.
  Vector3 p_r() const { return K_.tail<3>(); }
  /// Coordinate i of K(P), i ∈ {0, 1, 2, 3}.
  double operator[](int i) const { return K_[i]; }

  /// The conjugate P̄ = (p0, −p_r).
  Quaternion conjugate() const { return {K_[0], -K_[1], -K_[2], -K_[3]}; }
  /// The squared norm |P|² = P P̄ = p0² + p_rᵀ p_r.
  double squared_norm() const { return K_.squaredNorm(); }
  /// The norm |P|.
  double norm() const { return K_.norm(); }
  /// The inverse P⁻¹ = P̄ / |P|²; throws grbd::InvalidArgument for P = 0.
  Quaternion inverse() const;
  /// P / |P|; throws grbd::InvalidArgument for P = 0.
  Quaternion normalized() const;

  /// P ← P + Q (coordinate-wise).
  Quaternion& operator+=(const Quaternion& Q) { K_ += Q.K_; return *this; }
  /// P ← P − Q (coordinate-wise).
  Quaternion& operator-=(const Quaternion& Q) { K_ -= Q.K_; return *this; }
  /// P ← s P for a real s.
  Quaternion& operator*=(double s) { K_ *= s; return *this; }

 private:
  Vector4 K_;
};

/// The sum P + Q.
inline Quaternion operator+(Quaternion P, const Quaternion& Q) { return P += Q; }
/// The difference P − Q.
inline Quaternion operator-(Quaternion P, const Quaternion& Q) { return P -= Q; }
/// The negative −P (the same rotation as P).
inline Quaternion operator-(const Quaternion& P) { return Quaternion(Vector4(-P.coeffs())); }
/// The real multiple P s.
inline Quaternion operator*(Quaternion P, double s) { return P *= s; }
/// The real multiple s P.
inline Quaternion operator*(double s, Quaternion P) { return P *= s; }

// [product declaration]
/// \brief <b>Exercise 1.1</b>: the quaternion product.
///
/// The quaternion product P Q (Hamilton's product), in coordinates
/// \f[ K(PQ) = \begin{pmatrix} p_0 q_0 - \mathbf p_r^\mathsf{T}\mathbf q_r
///     \\ p_0\,\mathbf q_r + q_0\,\mathbf p_r + \mathbf p_r \times \mathbf q_r \end{pmatrix}. \f]
/// Associative and distributive, not commutative; |PQ| = |P| |Q|.
Quaternion product(const Quaternion& P, const Quaternion& Q);
// [product declaration]

/// The quaternion product P Q; see product().
inline Quaternion operator*(const Quaternion& P, const Quaternion& Q) { return product(P, Q); }

// [phi declaration]
/// \brief <b>Exercise 1.2</b>: the multiplication matrices φ_L and φ_R.
///
/// The left multiplication matrix φ_L(P) (4 × 4): K(PQ) = φ_L(P) K(Q),
/// \f[ \varphi_L(P) = \begin{pmatrix} p_0 & -\mathbf p_r^\mathsf{T}
///     \\ \mathbf p_r & p_0 \mathbf I + \tilde{\mathbf p}_r \end{pmatrix}. \f]
Matrix4 phi_L(const Quaternion& P);

/// \brief <b>Exercise 1.2</b>: the multiplication matrices φ_L and φ_R.
///
/// The right multiplication matrix φ_R(Q) (4 × 4): K(PQ) = φ_R(Q) K(P),
/// \f[ \varphi_R(Q) = \begin{pmatrix} q_0 & -\mathbf q_r^\mathsf{T}
///     \\ \mathbf q_r & q_0 \mathbf I - \tilde{\mathbf q}_r \end{pmatrix}. \f]
/// Associativity of ℍ is the commutation φ_L(P) φ_R(Q) = φ_R(Q) φ_L(P).
Matrix4 phi_R(const Quaternion& Q);
// [phi declaration]

/// The 2 × 2 complex matrix of P in the basis (I, i, j, k) of ℍ ⊂ ℂ²ˣ²:
/// \f[ P \mapsto \begin{pmatrix} p_0 + \mathrm i p_1 & p_2 + \mathrm i p_3
///                              \\ -p_2 + \mathrm i p_3 & p_0 - \mathrm i p_1 \end{pmatrix}, \f]
/// an injective algebra homomorphism: the matrix of PQ is the matrix product of those of P, Q.
Eigen::Matrix2cd complex_matrix(const Quaternion& P);

/// The inverse of complex_matrix(): reads P back from a matrix of the form above (the other two
/// entries are not checked).
Quaternion from_complex_matrix(const Eigen::Matrix2cd& M);

/// The rotation x ↦ P x Q of E⁴ for unit P, Q (4 × 1 in, 4 × 1 out): K(PXQ) = φ_L(P) φ_R(Q) K(X).
Vector4 rotate_E4(const Quaternion& P, const Vector4& x, const Quaternion& Q);

}  // namespace grbd::kinematics
