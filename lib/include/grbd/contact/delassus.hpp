#pragma once
/// \file
/// \brief The Delassus matrix W = Wᵀ M⁻¹ W of the body and compact forms, assembled in 3 × 3
/// blocks (chapter 5): what the direct linear solver of the Newton method factorizes, and the
/// local form of a body-form problem.
///
/// Block (i, j) is the velocity change of contact i per unit percussion of contact j,
/// W_ij = Σ_b σ_ib σ_jb W_ibᵀ M_b⁻¹ W_jb over the bodies b the two contacts share (σ = +1 for
/// side a, −1 for side b): nonzero only for contacts that touch a common body, so a sphere
/// packing with k contacts per sphere has about 2k − 1 blocks per row. The assembly costs
/// Σ_b k_b² block products over the bodies' contact counts k_b.

#include "grbd/contact/compact.hpp"
#include "grbd/contact/local_problem.hpp"
#include "grbd/contact/problem.hpp"

namespace grbd::contact {

/// Assembles W of a body-form problem into `W` (its vectors' capacity reused), every row's
/// blocks sorted by column, the diagonal block of every row stored. The contacts' body indices
/// are not checked: `problem` must be one that validate() accepted.
void assemble_delassus(const ContactProblem& problem, BlockSparseMatrix& W);

/// The same for a compact problem (chapter 6), whose W_s = [B; r̃_s B] in the world frame;
/// `problem` must be one that validate() accepted.
void assemble_delassus(const CompactProblem& problem, BlockSparseMatrix& W);

/// The body-form problem in local form, ξ = W Λ + q: W assembled, q = ξ(0) the free contact
/// velocities with the impact law's restitution (contact_velocities() of u_free), μ per contact.
/// Validates the problem first (InvalidArgument).
LocalProblem to_local(const ContactProblem& problem);

}  // namespace grbd::contact
