#pragma once
/// \file
/// \brief A small C++ wrapper over SUNDIALS 6.4: CVODE (BDF, Adams) and ARKODE (explicit and
/// IMEX Runge–Kutta) with RAII ownership, Eigen vectors, projection, and statistics (chapter 3).
///
/// Every SUNDIALS object (context, vectors, matrix, linear solver, integrator memory) is owned by
/// the solver object and freed in its destructor; every failing SUNDIALS call becomes a
/// grbd::ode::SundialsError that carries the flag's name and the solver's own message.

#include <functional>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "grbd/core/error.hpp"

namespace grbd::ode {

/// A SUNDIALS call failed: what() reads "<function> failed with <FLAG_NAME> (<flag>): <message>",
/// where the message is the one SUNDIALS' error handler reported.
class SundialsError : public Error {
 public:
  /// \param function  the SUNDIALS function that failed, e.g. "CVode"
  /// \param flag      its return flag
  /// \param flag_name the flag's name, e.g. "CV_TOO_MUCH_WORK"
  /// \param message   SUNDIALS' message for the failure (may be empty)
  SundialsError(const std::string& function, int flag, const std::string& flag_name,
                const std::string& message);
  /// The return flag.
  int flag() const noexcept { return flag_; }
  /// The flag's name, e.g. "CV_TOO_MUCH_WORK".
  const std::string& flag_name() const noexcept { return flag_name_; }

 private:
  int flag_;
  std::string flag_name_;
};

/// The right-hand side y' = f(t, y): writes f(t, y) into y_dot (both of the problem's size n).
/// May throw; the exception is carried through SUNDIALS and rethrown by advance().
using RhsFunction = std::function<void(double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                                       Eigen::Ref<Eigen::VectorXd> y_dot)>;

/// The projection onto the constraint manifold for CVodeSetProjFn: given the current solution y,
/// write into `correction` the change that moves y onto the manifold (y + correction on it).
/// `correction` arrives zeroed (size n), so only the entries that change need to be written.
/// May throw; the exception is carried through SUNDIALS and rethrown by advance().
using ProjectionFunction = std::function<void(double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                                              Eigen::Ref<Eigen::VectorXd> correction)>;

/// Error tolerances: the local error test is |e_i| ≤ rtol |y_i| + atol_i.
struct Tolerances {
  double rtol = 1e-6;           ///< relative tolerance ≥ 0
  double atol = 1e-10;          ///< absolute tolerance ≥ 0, used when atol_vector is empty
  Eigen::VectorXd atol_vector;  ///< per-component absolute tolerances (size n), optional
};

/// Integrator statistics, read from SUNDIALS after a run.
struct Statistics {
  long steps = 0;                 ///< accepted internal steps
  long rhs_evaluations = 0;       ///< every call of f (f_E and f_I together), those of the
                                  ///< difference-quotient Jacobians included
  long jacobian_evaluations = 0;  ///< Jacobian evaluations (difference quotients)
  long error_test_failures = 0;   ///< steps rejected by the local error test
  long nonlinear_iterations = 0;  ///< Newton or fixed-point iterations
  long nonlinear_convergence_failures = 0;  ///< failures of the nonlinear solver
  long projections = 0;                     ///< projections (CVODE with a projection function)
  double last_step = 0.0;                   ///< size of the last internal step
};

/// The linear multistep families of CVODE.
enum class CvodeMethod {
  bdf,    ///< backward differentiation formulas, orders 1–5, Newton with a dense direct solver;
          ///< the only family that supports a projection
  adams,  ///< Adams–Moulton, orders 1–12, fixed-point iteration (non-stiff problems)
};

/// CVODE on y' = f(t, y), y(t0) = y0.
///
/// Nothing is printed: SUNDIALS' error handler is replaced, and its messages end up in the
/// SundialsError that a failing call throws.
class Cvode {
 public:
  /// Sets up CVODE; throws grbd::InvalidArgument for an empty f, a non-finite t0, an empty or
  /// non-finite y0, a negative or non-finite tolerance, an atol_vector of the wrong size, or
  /// rtol = 0 with a zero absolute tolerance; SundialsError if SUNDIALS fails.
  Cvode(RhsFunction f, double t0, const Eigen::VectorXd& y0, CvodeMethod method,
        const Tolerances& tolerances);
  ~Cvode();
  Cvode(const Cvode&) = delete;
  Cvode& operator=(const Cvode&) = delete;

  /// Projects the solution after every step (CVodeSetProjFn); use it to keep |p| = 1. The output
  /// of advance(), which CVODE interpolates between its steps, is projected as well. CVODE 6.4
  /// projects with BDF only: throws grbd::InvalidArgument for Adams or an empty function. The
  /// error estimate is not projected (CVodeSetProjErrEst off).
  void set_projection(ProjectionFunction projection);
  /// The most internal steps between two output times (default 10⁵); max_steps > 0, else
  /// grbd::InvalidArgument. Exceeding it makes advance() throw SundialsError CV_TOO_MUCH_WORK.
  void set_max_steps(long max_steps);
  /// Integrates to t_out and returns y(t_out), interpolated by CVODE (CV_NORMAL). The first call
  /// fixes the direction of integration (t_out > t0 forward, < t0 backward); t_out must be finite
  /// and lie beyond time() in that direction, else grbd::InvalidArgument. A failure of CVODE
  /// throws SundialsError; an exception thrown by f or the projection is rethrown as it is.
  Eigen::VectorXd advance(double t_out);
  /// The current time: t0, then the last output time reached.
  double time() const;
  /// The statistics accumulated since construction.
  Statistics statistics() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// ARKODE's ARKStep on y' = f_E(t, y) + f_I(t, y): explicit Runge–Kutta when f_I is empty,
/// additive (IMEX) Runge–Kutta otherwise, with f_I treated implicitly by Newton's method and a
/// dense direct linear solver; diagonally implicit Runge–Kutta when f_E is empty. (Not ERKStep
/// for the explicit methods: SUNDIALS 6.4's ERKStep mistreats tables with c_s = 1 that are not
/// FSAL, llnl/sundials#311, and its 6th-order Verner pair converges at order 3.) Nothing is
/// printed, as for Cvode.
class Arkode {
 public:
  /// \param order the method order, one with a default table in ARKODE 5.4 (SUNDIALS 6.4):
  /// ERK 2, 3, 4, 5, 6 or 8 (Heun–Euler, Bogacki–Shampine, Zonneveld, Cash–Karp, Verner,
  /// Fehlberg); IMEX 3, 4 or 5 (Kennedy–Carpenter ARK3(2)4L[2]SA, ARK4(3)6L[2]SA,
  /// ARK5(4)8L[2]SA); DIRK 2 to 5. Any other order, both parts empty, or bad y0 or tolerances
  /// (as for Cvode) throw grbd::InvalidArgument; a failure of SUNDIALS throws SundialsError.
  Arkode(RhsFunction f_explicit, RhsFunction f_implicit, double t0, const Eigen::VectorXd& y0,
         int order, const Tolerances& tolerances);
  ~Arkode();
  Arkode(const Arkode&) = delete;
  Arkode& operator=(const Arkode&) = delete;

  /// The most internal steps between two output times (default 10⁵); max_steps > 0.
  void set_max_steps(long max_steps);
  /// Integrates to t_out and returns y(t_out); t_out as for Cvode::advance(), and the same
  /// errors. ARKODE steps exactly onto t_out (a stop time) rather than interpolating, since its
  /// dense output (Hermite, degree ≤ 5) is less accurate than its 6th- and 8th-order methods.
  Eigen::VectorXd advance(double t_out);
  /// The current time: t0, then the last output time reached.
  double time() const;
  /// The statistics accumulated since construction (nonlinear iterations and Jacobians: zero
  /// for ERK).
  Statistics statistics() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace grbd::ode
