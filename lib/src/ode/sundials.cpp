/// \file
/// \brief The SUNDIALS wrapper of chapter 3: CVODE (BDF with Newton and a dense direct solver,
/// Adams with fixed-point iteration) and ARKODE's ARKStep (explicit, IMEX and DIRK) behind RAII
/// classes, with the user's exceptions carried through the C callbacks and SUNDIALS' own error
/// messages carried into grbd::ode::SundialsError.
///
/// Ownership: every SUNDIALS object lives in a std::unique_ptr with the matching free function,
/// declared so that the integrator memory is freed first and the SUNContext last.

#include "grbd/ode/sundials.hpp"

#include <arkode/arkode_arkstep.h>
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <cmath>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>

#include "grbd/core/checks.hpp"

namespace grbd::ode {

namespace {

std::string compose_message(const std::string& function, int flag, const std::string& flag_name,
                            const std::string& message) {
  std::string what = function + " failed with " + flag_name + " (" + std::to_string(flag) + ")";
  if (!message.empty()) what += ": " + message;
  return what;
}

}  // namespace

SundialsError::SundialsError(const std::string& function, int flag, const std::string& flag_name,
                             const std::string& message)
    : Error(compose_message(function, flag, flag_name, message)),
      flag_(flag),
      flag_name_(flag_name) {}

namespace {

// ---------------------------------------------------------------------------------------------
// Ownership of the SUNDIALS objects
// ---------------------------------------------------------------------------------------------

struct FreeContext {
  void operator()(SUNContext context) const { SUNContext_Free(&context); }
};
struct FreeVector {
  void operator()(N_Vector v) const { N_VDestroy(v); }
};
struct FreeMatrix {
  void operator()(SUNMatrix A) const { SUNMatDestroy(A); }
};
struct FreeLinearSolver {
  void operator()(SUNLinearSolver solver) const { SUNLinSolFree(solver); }
};
struct FreeNonlinearSolver {
  void operator()(SUNNonlinearSolver solver) const { SUNNonlinSolFree(solver); }
};

using Context = std::unique_ptr<std::remove_pointer_t<SUNContext>, FreeContext>;
using Vector = std::unique_ptr<std::remove_pointer_t<N_Vector>, FreeVector>;
using Matrix = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, FreeMatrix>;
using LinearSolver = std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, FreeLinearSolver>;
using NonlinearSolver =
    std::unique_ptr<std::remove_pointer_t<SUNNonlinearSolver>, FreeNonlinearSolver>;
/// The integrator memory (void* in SUNDIALS) with its family's free function.
using Memory = std::unique_ptr<void, void (*)(void*)>;

void free_cvode(void* mem) { CVodeFree(&mem); }
void free_arkstep(void* mem) { ARKStepFree(&mem); }

/// The names of a return flag: CVodeGetReturnFlagName and friends return a malloc'ed string.
using FlagNamer = char* (*)(long int);

std::string flag_name(FlagNamer namer, int flag) {
  const std::unique_ptr<char, void (*)(void*)> name(namer(flag), std::free);
  return name ? std::string(name.get()) : std::string("UNKNOWN");
}

Eigen::Map<Eigen::VectorXd> view(N_Vector v) {
  return {N_VGetArrayPointer(v), static_cast<Eigen::Index>(N_VGetLength(v))};
}

// ---------------------------------------------------------------------------------------------
// The C callbacks
// ---------------------------------------------------------------------------------------------

// [error handler]
/// What the C callbacks reach through SUNDIALS' user_data: the user's functions, the exception
/// one of them threw, and the message of SUNDIALS' error handler.
struct Callbacks {
  RhsFunction f;                  ///< CVODE's f; ARKODE's explicit part f_E
  RhsFunction f_implicit;         ///< ARKODE's implicit part f_I
  ProjectionFunction projection;  ///< CVODE's projection
  std::exception_ptr exception;   ///< thrown by f, f_implicit or projection, not yet rethrown
  std::string message;            ///< SUNDIALS' message for the last failure

  /// Rethrows (once) the exception a callback stored: it takes precedence over SUNDIALS' flag,
  /// which only says that the callback failed.
  void rethrow_pending() {
    if (exception) std::rethrow_exception(std::exchange(exception, nullptr));
  }

  /// Runs one SUNDIALS call and turns a negative flag into a SundialsError that carries the
  /// flag's name and the message the error handler captured during the call.
  template <typename Call>
  void check(const char* function, FlagNamer namer, Call&& call) {
    message.clear();
    const int flag = call();
    rethrow_pending();
    if (flag < 0) throw SundialsError(function, flag, flag_name(namer, flag), message);
  }
};

/// SUNDIALS calls the error handler before a failing function returns; the default handler
/// prints to stderr. This one prints nothing: it keeps the message of a failure (negative
/// code) for the SundialsError thrown next and drops warnings (positive codes).
void error_handler(int error_code, const char* /*module*/, const char* /*function*/, char* message,
                   void* user_data) {
  if (error_code >= 0 || user_data == nullptr) return;
  try {
    static_cast<Callbacks*>(user_data)->message = message != nullptr ? message : "";
  } catch (...) {
    // Out of memory while copying a message: nothing may propagate into C; keep the old one.
  }
}

/// Calls f(t, y, y_dot) for SUNDIALS. A C++ exception must not unwind through SUNDIALS' C
/// frames: it is stored and −1 ("unrecoverable failure") returned, so that the integrator stops
/// and the wrapper rethrows the exception from advance().
int call_rhs(const RhsFunction& f, Callbacks& callbacks, sunrealtype t, N_Vector y,
             N_Vector y_dot) noexcept {
  // SUNDIALS treats some failures of f as recoverable (a failed difference-quotient Jacobian
  // makes ARKODE retry with a smaller step): once f has thrown, fail at once, without calling
  // the user's code again, so that the integrator gives up and the exception surfaces.
  if (callbacks.exception) return -1;
  try {
    Eigen::Map<Eigen::VectorXd> y_dot_view = view(y_dot);
    f(t, view(y), y_dot_view);
    return 0;
  } catch (...) {
    callbacks.exception = std::current_exception();
    return -1;
  }
}

int rhs_callback(sunrealtype t, N_Vector y, N_Vector y_dot, void* user_data) {
  auto& callbacks = *static_cast<Callbacks*>(user_data);
  return call_rhs(callbacks.f, callbacks, t, y, y_dot);
}

int implicit_rhs_callback(sunrealtype t, N_Vector y, N_Vector y_dot, void* user_data) {
  auto& callbacks = *static_cast<Callbacks*>(user_data);
  return call_rhs(callbacks.f_implicit, callbacks, t, y, y_dot);
}
// [error handler]

// [projection callback]
/// CVODE's projection (CVProjFn): after each accepted step CVODE hands over the new solution y
/// and applies y ← y + correction. The correction arrives zeroed, so the user's function needs
/// to write only the entries it changes. The error estimate is not projected (CVodeSetProjErrEst
/// is switched off), hence `error` is unused; eps_proj, CVODE's tolerance for an iterative
/// projection, too, since the projections here are closed-form.
int projection_callback(sunrealtype t, N_Vector y, N_Vector correction, sunrealtype /*eps_proj*/,
                        N_Vector /*error*/, void* user_data) {
  auto& callbacks = *static_cast<Callbacks*>(user_data);
  if (callbacks.exception) return -1;
  try {
    Eigen::Map<Eigen::VectorXd> correction_view = view(correction);
    correction_view.setZero();
    callbacks.projection(t, view(y), correction_view);
    return 0;
  } catch (...) {
    callbacks.exception = std::current_exception();
    return -1;  // CV_PROJFUNC_FAIL: unrecoverable
  }
}
// [projection callback]

// ---------------------------------------------------------------------------------------------
// Input validation
// ---------------------------------------------------------------------------------------------

void require_tolerances(const Tolerances& tolerances, Eigen::Index n, const std::string& where) {
  if (!std::isfinite(tolerances.rtol) || tolerances.rtol < 0.0) {
    throw InvalidArgument(where + ": the relative tolerance must be finite and >= 0, but rtol = " +
                          format_number(tolerances.rtol));
  }
  bool some_atol_zero = false;
  if (tolerances.atol_vector.size() == 0) {
    if (!std::isfinite(tolerances.atol) || tolerances.atol < 0.0) {
      throw InvalidArgument(where +
                            ": the absolute tolerance must be finite and >= 0, but atol = " +
                            format_number(tolerances.atol));
    }
    some_atol_zero = tolerances.atol == 0.0;
  } else {
    if (tolerances.atol_vector.size() != n) {
      throw InvalidArgument(where + ": atol_vector must have one entry per unknown (" +
                            std::to_string(n) + "), but it has " +
                            std::to_string(tolerances.atol_vector.size()));
    }
    for (Eigen::Index i = 0; i < n; ++i) {
      const double atol = tolerances.atol_vector[i];
      if (!std::isfinite(atol) || atol < 0.0) {
        throw InvalidArgument(where + ": atol_vector[" + std::to_string(i) +
                              "] must be finite and >= 0, but it is " + format_number(atol));
      }
      some_atol_zero = some_atol_zero || atol == 0.0;
    }
  }
  // The error weights are 1/(rtol |y_i| + atol_i): with rtol = 0 a zero atol_i makes the weight
  // infinite for every y.
  if (tolerances.rtol == 0.0 && some_atol_zero) {
    throw InvalidArgument(where + ": with rtol = 0 every absolute tolerance must be positive");
  }
}

void require_initial_value(double t0, const Eigen::VectorXd& y0, const std::string& where) {
  if (!std::isfinite(t0)) {
    throw InvalidArgument(where +
                          ": the initial time must be finite, but t0 = " + format_number(t0));
  }
  if (y0.size() == 0) throw InvalidArgument(where + ": the initial value y0 is empty");
  for (Eigen::Index i = 0; i < y0.size(); ++i) {
    if (!std::isfinite(y0[i])) {
      throw InvalidArgument(where + ": y0[" + std::to_string(i) + "] must be finite, but it is " +
                            format_number(y0[i]));
    }
  }
}

void require_max_steps(long max_steps, const std::string& where) {
  if (max_steps <= 0) {
    throw InvalidArgument(where + ": the maximum number of steps must be positive, but it is " +
                          std::to_string(max_steps));
  }
}

/// What CVODE and ARKODE share: the callbacks, the SUNDIALS objects, and the output time.
struct Solver {
  Callbacks callbacks;
  Context context{nullptr};
  Vector y{nullptr};  ///< y0 on entry, then the solution at the last output time
  Matrix A{nullptr};
  LinearSolver linear_solver{nullptr};
  NonlinearSolver nonlinear_solver{nullptr};
  Memory mem{nullptr, free_cvode};  ///< declared last: freed first
  double t = 0.0;                   ///< time of the last output (t0 before the first)
  int direction = 0;                ///< +1 or −1 once the first output time is known

  /// The context and the vector y = y0.
  Solver(double t0, const Eigen::VectorXd& y0) : t(t0) {
    SUNContext raw = nullptr;
    // No MPI communicator: a serial problem (SUNDIALS 6.4 takes a void* for MPI_Comm).
    const int flag = SUNContext_Create(nullptr, &raw);
    if (flag != 0 || raw == nullptr) {
      throw SundialsError("SUNContext_Create", flag, "NULL", "no SUNDIALS context was created");
    }
    context.reset(raw);
    y.reset(created(N_VNew_Serial(y0.size(), context.get()), "N_VNew_Serial"));
    view(y.get()) = y0;
  }

  /// Throws unless SUNDIALS returned an object.
  template <typename T>
  static T created(T object, const char* function) {
    if (object == nullptr) {
      throw SundialsError(function, 0, "NULL", "no object was created (out of memory?)");
    }
    return object;
  }

  /// The dense matrix and direct solver of the Newton iterations.
  void make_dense_linear_solver() {
    const auto n = N_VGetLength(y.get());
    A.reset(created(SUNDenseMatrix(n, n, context.get()), "SUNDenseMatrix"));
    linear_solver.reset(
        created(SUNLinSol_Dense(y.get(), A.get(), context.get()), "SUNLinSol_Dense"));
  }

  /// Throws unless t_out lies beyond the last output time in the direction of integration.
  void require_output_time(double t_out, const char* where) {
    if (!std::isfinite(t_out)) {
      throw InvalidArgument(std::string(where) + ": t_out must be finite, but it is " +
                            format_number(t_out));
    }
    const int step_direction = t_out > t ? 1 : (t_out < t ? -1 : 0);
    if (step_direction == 0 || (direction != 0 && step_direction != direction)) {
      throw InvalidArgument(std::string(where) + ": t_out = " + format_number(t_out) +
                            " must lie beyond the current time " + format_number(t) +
                            (direction < 0 ? " (integrating backward)" : " (integrating forward)"));
    }
  }

  /// A tolerance vector for the SVtolerances functions, which copy it.
  Vector tolerance_vector(const Eigen::VectorXd& atol) const {
    Vector v(created(N_VNew_Serial(atol.size(), context.get()), "N_VNew_Serial"));
    view(v.get()) = atol;
    return v;
  }

  Eigen::VectorXd solution() const { return view(y.get()); }
};

}  // namespace

// =============================================================================================
// CVODE
// =============================================================================================

struct Cvode::Impl : Solver {
  CvodeMethod method;
  bool has_projection = false;

  Impl(double t0, const Eigen::VectorXd& y0, CvodeMethod m) : Solver(t0, y0), method(m) {}

  template <typename Call>
  void check(const char* function, Call&& call) {
    callbacks.check(function, CVodeGetReturnFlagName, std::forward<Call>(call));
  }
};

Cvode::Cvode(RhsFunction f, double t0, const Eigen::VectorXd& y0, CvodeMethod method,
             const Tolerances& tolerances) {
  if (!f) throw InvalidArgument("Cvode: the right-hand side f is empty");
  if (method != CvodeMethod::bdf && method != CvodeMethod::adams) {
    throw InvalidArgument("Cvode: unknown method " + std::to_string(static_cast<int>(method)));
  }
  require_initial_value(t0, y0, "Cvode");
  require_tolerances(tolerances, y0.size(), "Cvode");

  impl_ = std::make_unique<Impl>(t0, y0, method);
  Impl& s = *impl_;
  s.callbacks.f = std::move(f);
  s.mem = Memory(
      Solver::created(CVodeCreate(method == CvodeMethod::bdf ? CV_BDF : CV_ADAMS, s.context.get()),
                      "CVodeCreate"),
      free_cvode);
  void* mem = s.mem.get();
  // The error handler first, so that no later failure prints to stderr.
  s.check("CVodeSetErrHandlerFn",
          [&] { return CVodeSetErrHandlerFn(mem, error_handler, &s.callbacks); });
  s.check("CVodeSetUserData", [&] { return CVodeSetUserData(mem, &s.callbacks); });
  s.check("CVodeInit", [&] { return CVodeInit(mem, rhs_callback, t0, s.y.get()); });
  if (tolerances.atol_vector.size() == 0) {
    s.check("CVodeSStolerances",
            [&] { return CVodeSStolerances(mem, tolerances.rtol, tolerances.atol); });
  } else {
    const Vector atol = s.tolerance_vector(tolerances.atol_vector);
    s.check("CVodeSVtolerances",
            [&] { return CVodeSVtolerances(mem, tolerances.rtol, atol.get()); });
  }
  if (method == CvodeMethod::bdf) {
    // Newton's method (CVODE's default nonlinear solver) with difference-quotient Jacobians and
    // a dense LU: BDF is meant for stiff problems, where fixed-point iteration would force tiny
    // steps.
    s.make_dense_linear_solver();
    s.callbacks.check("CVodeSetLinearSolver", CVodeGetLinReturnFlagName,
                      [&] { return CVodeSetLinearSolver(mem, s.linear_solver.get(), s.A.get()); });
  } else {
    // Adams is for non-stiff problems: fixed-point (functional) iteration needs no Jacobian.
    // m = 0: no Anderson acceleration.
    s.nonlinear_solver.reset(Solver::created(SUNNonlinSol_FixedPoint(s.y.get(), 0, s.context.get()),
                                             "SUNNonlinSol_FixedPoint"));
    s.check("CVodeSetNonlinearSolver",
            [&] { return CVodeSetNonlinearSolver(mem, s.nonlinear_solver.get()); });
  }
  s.check("CVodeSetMaxNumSteps", [&] { return CVodeSetMaxNumSteps(mem, 100000); });
}

Cvode::~Cvode() = default;

void Cvode::set_projection(ProjectionFunction projection) {
  if (!projection) throw InvalidArgument("Cvode::set_projection: the projection is empty");
  // CVODE 6.4 supports projection with BDF only (CVodeSetProjFn fails with CV_ILL_INPUT for
  // Adams); say so in grbd's words rather than CVODE's.
  if (impl_->method != CvodeMethod::bdf) {
    throw InvalidArgument(
        "Cvode::set_projection: CVODE supports projection with CvodeMethod::bdf only, not with "
        "CvodeMethod::adams");
  }
  void* mem = impl_->mem.get();
  impl_->callbacks.projection = std::move(projection);
  impl_->check("CVodeSetProjFn", [&] { return CVodeSetProjFn(mem, projection_callback); });
  // The user's function projects y only; leave CVODE's error estimate as it is.
  impl_->check("CVodeSetProjErrEst", [&] { return CVodeSetProjErrEst(mem, SUNFALSE); });
  impl_->has_projection = true;
}

void Cvode::set_max_steps(long max_steps) {
  require_max_steps(max_steps, "Cvode::set_max_steps");
  void* mem = impl_->mem.get();
  impl_->check("CVodeSetMaxNumSteps", [&] { return CVodeSetMaxNumSteps(mem, max_steps); });
}

// [cvode advance]
Eigen::VectorXd Cvode::advance(double t_out) {
  Impl& s = *impl_;
  s.require_output_time(t_out, "Cvode::advance");
  // CV_NORMAL: CVODE chooses its own steps, steps past t_out and interpolates y(t_out) from its
  // history array, so the output times do not constrain the step sizes.
  double t_reached = s.t;
  s.check("CVode", [&] { return CVode(s.mem.get(), t_out, s.y.get(), &t_reached, CV_NORMAL); });
  s.direction = t_out > s.t ? 1 : -1;
  s.t = t_reached;
  Eigen::VectorXd y = s.solution();
  if (s.has_projection) {
    // CVODE projects the solution at its steps, not the interpolated output between them, which
    // is off the manifold by the local error: project the output too.
    Eigen::VectorXd correction = Eigen::VectorXd::Zero(y.size());
    s.callbacks.projection(t_reached, y, correction);
    y += correction;
  }
  return y;
}
// [cvode advance]

double Cvode::time() const { return impl_->t; }

Statistics Cvode::statistics() const {
  Impl& s = *impl_;
  void* mem = s.mem.get();
  Statistics stats;
  s.check("CVodeGetNumSteps", [&] { return CVodeGetNumSteps(mem, &stats.steps); });
  s.check("CVodeGetNumRhsEvals", [&] { return CVodeGetNumRhsEvals(mem, &stats.rhs_evaluations); });
  s.check("CVodeGetNumErrTestFails",
          [&] { return CVodeGetNumErrTestFails(mem, &stats.error_test_failures); });
  s.check("CVodeGetNumNonlinSolvIters",
          [&] { return CVodeGetNumNonlinSolvIters(mem, &stats.nonlinear_iterations); });
  s.check("CVodeGetNumNonlinSolvConvFails", [&] {
    return CVodeGetNumNonlinSolvConvFails(mem, &stats.nonlinear_convergence_failures);
  });
  if (s.method == CvodeMethod::bdf) {
    // The difference-quotient Jacobian calls f too; count every call of f.
    long jacobian_rhs = 0;
    s.check("CVodeGetNumJacEvals",
            [&] { return CVodeGetNumJacEvals(mem, &stats.jacobian_evaluations); });
    s.check("CVodeGetNumLinRhsEvals", [&] { return CVodeGetNumLinRhsEvals(mem, &jacobian_rhs); });
    stats.rhs_evaluations += jacobian_rhs;
  }
  if (s.has_projection) {
    s.check("CVodeGetNumProjEvals", [&] { return CVodeGetNumProjEvals(mem, &stats.projections); });
  }
  s.check("CVodeGetLastStep", [&] { return CVodeGetLastStep(mem, &stats.last_step); });
  return stats;
}

// =============================================================================================
// ARKODE
// =============================================================================================

namespace {

/// Which ARKODE stepper a pair (f_E, f_I) selects.
enum class ArkodeKind { explicit_rk, imex, implicit_rk };

}  // namespace

struct Arkode::Impl : Solver {
  ArkodeKind kind;

  Impl(double t0, const Eigen::VectorXd& y0, ArkodeKind k) : Solver(t0, y0), kind(k) {}

  template <typename Call>
  void check(const char* function, Call&& call) {
    callbacks.check(function, ARKStepGetReturnFlagName, std::forward<Call>(call));
  }
};

Arkode::Arkode(RhsFunction f_explicit, RhsFunction f_implicit, double t0, const Eigen::VectorXd& y0,
               int order, const Tolerances& tolerances) {
  if (!f_explicit && !f_implicit) {
    throw InvalidArgument("Arkode: both parts of the right-hand side, f_E and f_I, are empty");
  }
  const ArkodeKind kind = !f_implicit  ? ArkodeKind::explicit_rk
                          : f_explicit ? ArkodeKind::imex
                                       : ArkodeKind::implicit_rk;
  // ARKODE 5.4 (SUNDIALS 6.4) has default tables for these orders only; for any other it warns
  // and silently substitutes another order, so refuse it here.
  switch (kind) {
    case ArkodeKind::explicit_rk:
      if (order < 2 || order > 8 || order == 7) {
        throw InvalidArgument(
            "Arkode: explicit Runge–Kutta has orders 2, 3, 4, 5, 6 "
            "and 8, but order = " +
            std::to_string(order));
      }
      break;
    case ArkodeKind::imex:
      if (order < 3 || order > 5) {
        throw InvalidArgument(
            "Arkode: additive (IMEX) Runge–Kutta has orders 3, 4 and 5, but "
            "order = " +
            std::to_string(order));
      }
      break;
    case ArkodeKind::implicit_rk:
      if (order < 2 || order > 5) {
        throw InvalidArgument(
            "Arkode: diagonally implicit Runge–Kutta has orders 2 to 5, but "
            "order = " +
            std::to_string(order));
      }
      break;
  }
  require_initial_value(t0, y0, "Arkode");
  require_tolerances(tolerances, y0.size(), "Arkode");

  impl_ = std::make_unique<Impl>(t0, y0, kind);
  Impl& s = *impl_;
  s.callbacks.f = std::move(f_explicit);
  s.callbacks.f_implicit = std::move(f_implicit);
  // ARKStep for the explicit methods too, not ERKStep: in SUNDIALS 6.4 ERKStep reuses the last
  // stage as the next step's first whenever c_s = 1, also for tables that are not FSAL
  // (llnl/sundials issue #311, fixed in later releases), which turns Verner's 6th-order pair
  // into a 3rd-order method. ARKStep with an empty f_I steps the same tables correctly.
  // The stepper is created and initialised in one call, before an error handler can be set;
  // the inputs are validated above, so that call does not fail on them.
  s.mem =
      Memory(Solver::created(
                 ARKStepCreate(kind == ArkodeKind::implicit_rk ? nullptr : rhs_callback,
                               kind == ArkodeKind::explicit_rk ? nullptr : implicit_rhs_callback,
                               t0, s.y.get(), s.context.get()),
                 "ARKStepCreate"),
             free_arkstep);
  void* mem = s.mem.get();
  s.check("ARKStepSetErrHandlerFn",
          [&] { return ARKStepSetErrHandlerFn(mem, error_handler, &s.callbacks); });
  s.check("ARKStepSetUserData", [&] { return ARKStepSetUserData(mem, &s.callbacks); });
  if (tolerances.atol_vector.size() == 0) {
    s.check("ARKStepSStolerances",
            [&] { return ARKStepSStolerances(mem, tolerances.rtol, tolerances.atol); });
  } else {
    const Vector atol = s.tolerance_vector(tolerances.atol_vector);
    s.check("ARKStepSVtolerances",
            [&] { return ARKStepSVtolerances(mem, tolerances.rtol, atol.get()); });
  }
  if (kind != ArkodeKind::explicit_rk) {
    // f_I is solved by ARKStep's default Newton iteration with difference-quotient Jacobians of
    // f_I and a dense LU.
    s.make_dense_linear_solver();
    s.callbacks.check("ARKStepSetLinearSolver", ARKStepGetLinReturnFlagName, [&] {
      return ARKStepSetLinearSolver(mem, s.linear_solver.get(), s.A.get());
    });
  }
  s.check("ARKStepSetOrder", [&] { return ARKStepSetOrder(mem, order); });
  s.check("ARKStepSetMaxNumSteps", [&] { return ARKStepSetMaxNumSteps(mem, 100000); });
}

Arkode::~Arkode() = default;

void Arkode::set_max_steps(long max_steps) {
  require_max_steps(max_steps, "Arkode::set_max_steps");
  void* mem = impl_->mem.get();
  impl_->check("ARKStepSetMaxNumSteps", [&] { return ARKStepSetMaxNumSteps(mem, max_steps); });
}

Eigen::VectorXd Arkode::advance(double t_out) {
  Impl& s = *impl_;
  s.require_output_time(t_out, "Arkode::advance");
  // A stop time makes ARKODE step exactly onto t_out instead of interpolating: its dense output
  // (a Hermite polynomial of degree ≤ 5) would spoil the 6th- and 8th-order methods (with the
  // 8th-order table at rtol 1e-10, DETEST B5 loses three digits to the interpolant).
  double t_reached = s.t;
  s.check("ARKStepSetStopTime", [&] { return ARKStepSetStopTime(s.mem.get(), t_out); });
  s.check("ARKStepEvolve",
          [&] { return ARKStepEvolve(s.mem.get(), t_out, s.y.get(), &t_reached, ARK_NORMAL); });
  s.direction = t_out > s.t ? 1 : -1;
  s.t = t_reached;
  return s.solution();
}

double Arkode::time() const { return impl_->t; }

Statistics Arkode::statistics() const {
  Impl& s = *impl_;
  void* mem = s.mem.get();
  Statistics stats;
  long explicit_rhs = 0;
  long implicit_rhs = 0;
  long jacobian_rhs = 0;
  s.check("ARKStepGetNumSteps", [&] { return ARKStepGetNumSteps(mem, &stats.steps); });
  s.check("ARKStepGetNumRhsEvals",
          [&] { return ARKStepGetNumRhsEvals(mem, &explicit_rhs, &implicit_rhs); });
  s.check("ARKStepGetNumErrTestFails",
          [&] { return ARKStepGetNumErrTestFails(mem, &stats.error_test_failures); });
  s.check("ARKStepGetLastStep", [&] { return ARKStepGetLastStep(mem, &stats.last_step); });
  if (s.kind != ArkodeKind::explicit_rk) {
    s.check("ARKStepGetNumLinRhsEvals",
            [&] { return ARKStepGetNumLinRhsEvals(mem, &jacobian_rhs); });
    s.check("ARKStepGetNumJacEvals",
            [&] { return ARKStepGetNumJacEvals(mem, &stats.jacobian_evaluations); });
    s.check("ARKStepGetNumNonlinSolvIters",
            [&] { return ARKStepGetNumNonlinSolvIters(mem, &stats.nonlinear_iterations); });
    s.check("ARKStepGetNumNonlinSolvConvFails", [&] {
      return ARKStepGetNumNonlinSolvConvFails(mem, &stats.nonlinear_convergence_failures);
    });
  }
  // Every call of f_E and of f_I, the difference quotients of the Jacobian of f_I included.
  stats.rhs_evaluations = explicit_rhs + implicit_rhs + jacobian_rhs;
  return stats;
}

}  // namespace grbd::ode
