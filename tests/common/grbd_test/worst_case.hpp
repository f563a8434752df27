#pragma once
/// \file
/// \brief The worst error of a randomised property test, with the input that produced it.
///
/// A property test that loops over seeded samples and keeps only the largest error reports, when
/// it fails, just a number. WorstCase keeps the number and a description of the input behind it,
/// so that the failure message says which sample failed:
///
///     grbd::test::WorstCase worst;
///     for (int n = 0; n < kSamples; ++n) {
///       const Quaternion P = rng.quaternion();
///       const Quaternion Q = rng.quaternion();
///       worst.update(distance(P * Q, reference_product(P, Q)) / (P.norm() * Q.norm()), n,
///                    [&] { return describe("P", P, "Q", Q); });
///     }
///     EXPECT_LE(worst.value(), kRel) << worst;
///
/// prints, on failure, "worst error 3.1e-12 at sample 17: P = (…), Q = (…)".
///
/// Unlike `worst = std::max(worst, error)`, which silently drops a NaN error (every comparison
/// with NaN is false), a NaN error is worse than any number: value() is then NaN, and
/// EXPECT_LE(NaN, tol) fails. The description is built only when an error is a new worst, a
/// handful of times per test, so the passing case stays cheap.

#include <Eigen/Core>
#include <cmath>
#include <complex>
#include <concepts>
#include <cstddef>
#include <iomanip>
#include <iterator>
#include <limits>
#include <ostream>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "grbd/kinematics/quaternion.hpp"

namespace grbd::test {

/// The largest error seen so far and a description of the input that produced it.
class WorstCase {
 public:
  /// Starts from 0 (as `double worst = 0.0;`): value() is the largest of 0 and every error.
  WorstCase() = default;
  /// Starts from `initial` (as `double worst = initial;`): value() is the largest of `initial`
  /// and every error passed to update().
  explicit WorstCase(double initial) : worst_(initial) {}

  /// Records `error` for the input of sample number `sample` of the loop (a negative `sample`
  /// stands for none); if it is a new worst (or the first NaN), stores `describe()`, a callable
  /// returning something convertible to std::string, as the description of the input. The
  /// message then reads "... at sample <sample>: <description>". Returns whether it was a new
  /// worst.
  template <class Describe>
  bool update(double error, long long sample, Describe&& describe) {
    if (!is_new_worst(error)) return false;
    record(error, sample, std::string(std::forward<Describe>(describe)()));
    return true;
  }

  /// As update(error, sample, describe), for an input that is not a numbered sample.
  template <class Describe>
  bool update(double error, Describe&& describe) {
    return update(error, -1, std::forward<Describe>(describe));
  }

  /// The worst error: the largest one seen (at least the initial value), NaN if any was NaN.
  double value() const { return nan_ ? std::numeric_limits<double>::quiet_NaN() : worst_; }
  /// The description of the worst input (empty if there is none).
  const std::string& input() const { return input_; }

  /// "worst error 3.1e-12 at sample 17: P = (…), Q = (…)", for a GoogleTest failure message.
  friend std::ostream& operator<<(std::ostream& os, const WorstCase& w) {
    std::ostringstream s;  // leaves the stream's formatting alone
    s << std::setprecision(3) << "worst error " << w.value();
    if (!w.has_input_) {
      s << " (no error above the initial value)";
    } else {
      if (w.nan_) s << " (first NaN)";
      if (w.sample_ >= 0) {
        s << " at sample " << w.sample_ << (w.input_.empty() ? "" : ": ") << w.input_;
      } else if (!w.input_.empty()) {
        s << " at " << w.input_;
      }
    }
    return os << s.str();
  }

 private:
  bool is_new_worst(double error) const {
    if (nan_) return false;  // the first NaN stays the worst
    if (std::isnan(error)) return true;
    return error > worst_ || (!has_input_ && error == worst_);
  }
  void record(double error, long long sample, std::string input) {
    if (std::isnan(error)) {
      nan_ = true;
    } else {
      worst_ = error;
    }
    has_input_ = true;
    sample_ = sample;
    input_ = std::move(input);
  }

  double worst_ = 0.0;
  bool nan_ = false;
  bool has_input_ = false;
  long long sample_ = -1;
  std::string input_;
};

/// Teaches describe() a type T of the project (see bodies.hpp): specialise it with
/// `static void put(std::ostream& os, const T& x)`, e.g. writing `describe("m", x.m, ...)` in
/// parentheses. Specialise it before the first describe() of a T.
template <class T>
struct Describer;

namespace detail {

template <class T>
concept HasDescriber = requires(std::ostream& os, const T& x) { Describer<T>::put(os, x); };

template <class Derived>
std::true_type is_eigen_dense(const Eigen::DenseBase<Derived>*);
std::false_type is_eigen_dense(...);

/// An Eigen vector, matrix or expression (deduced from the base, so that no Eigen template is
/// instantiated for other types).
template <class T>
concept EigenDense = decltype(is_eigen_dense(std::declval<const T*>()))::value;

template <class T>
concept Streamable = requires(std::ostream& os, const T& x) { os << x; };

template <class T>
concept Range = requires(const T& x) {
  std::begin(x);
  std::end(x);
};

template <class T>
struct IsComplex : std::false_type {};
template <class T>
struct IsComplex<std::complex<T>> : std::true_type {};

/// A scalar with every digit that tells it apart (max_digits10); integers and bools as usual.
template <class T>
void put_scalar(std::ostream& os, const T& x) {
  using S = std::remove_cvref_t<T>;
  if constexpr (std::is_same_v<S, bool>) {
    os << (x ? "true" : "false");
  } else if constexpr (std::is_floating_point_v<S>) {
    os << std::setprecision(std::numeric_limits<S>::max_digits10) << x;
  } else if constexpr (IsComplex<S>::value) {
    put_scalar(os, x.real());
    os << (std::signbit(x.imag()) ? " - " : " + ");
    put_scalar(os, std::abs(x.imag()));
    os << "i";
  } else {
    os << x;
  }
}

template <class T>
void put_value(std::ostream& os, const T& x);

/// The items 0 … n − 1 of a list, each written by put_item(k), as [a, b, c].
template <class PutItem>
void put_list(std::ostream& os, Eigen::Index n, PutItem&& put_item) {
  os << "[";
  for (Eigen::Index k = 0; k < n; ++k) {
    if (k > 0) os << ", ";
    put_item(k);
  }
  os << "]";
}

/// A vector as [a, b, c]; a matrix as its rows, [[a, b], [c, d]].
template <class Derived>
void put_eigen(std::ostream& os, const Eigen::DenseBase<Derived>& x) {
  const auto& A = x.derived().eval();
  if (A.cols() == 1 || A.rows() == 1) {
    put_list(os, A.size(), [&](Eigen::Index k) { put_scalar(os, A(k)); });
    return;
  }
  put_list(os, A.rows(), [&](Eigen::Index i) {
    put_list(os, A.cols(), [&](Eigen::Index j) { put_scalar(os, A(i, j)); });
  });
}

/// Dispatch: strings as they are; Eigen vectors and matrices; quaternions as (p0, p1, p2, p3);
/// numbers with full precision; types with a Describer; anything with operator<<; ranges of any
/// of these as {a, b}.
template <class T>
void put_value(std::ostream& os, const T& x) {
  using S = std::remove_cvref_t<T>;
  if constexpr (std::is_convertible_v<const S&, std::string_view>) {
    os << std::string_view(x);
  } else if constexpr (EigenDense<S>) {
    put_eigen(os, x);
  } else if constexpr (std::is_same_v<S, kinematics::Quaternion>) {
    os << "(";
    for (int i = 0; i < 4; ++i) {
      if (i > 0) os << ", ";
      put_scalar(os, x[i]);
    }
    os << ")";
  } else if constexpr (std::is_arithmetic_v<S> || IsComplex<S>::value) {
    put_scalar(os, x);
  } else if constexpr (HasDescriber<S>) {
    Describer<S>::put(os, x);
  } else if constexpr (std::is_enum_v<S> && !Streamable<S>) {
    os << static_cast<std::underlying_type_t<S>>(x);
  } else if constexpr (Streamable<S>) {
    os << std::setprecision(std::numeric_limits<double>::max_digits10) << x;
  } else if constexpr (Range<S>) {
    os << "{";
    bool first = true;
    for (const auto& item : x) {
      if (!first) os << ", ";
      first = false;
      put_value(os, item);
    }
    os << "}";
  } else {
    static_assert(Range<S>, "describe(): no way to print this type");
  }
}

inline void put_pairs(std::ostream&) {}

template <class Value, class... Rest>
void put_pairs(std::ostream& os, std::string_view name, const Value& value, const Rest&... rest) {
  os << name << " = ";
  put_value(os, value);
  if constexpr (sizeof...(Rest) > 0) {
    os << ", ";
    put_pairs(os, rest...);
  }
}

}  // namespace detail

/// Describes inputs compactly and with full precision, as "name = value" pairs:
/// describe("P", P, "Q", Q, "h", h) gives "P = (p0, p1, p2, p3), Q = (…), h = 0.125".
/// Doubles get max_digits10 digits (they read back to the same double); Eigen vectors print as
/// [a, b, c], matrices by rows as [[a, b], [c, d]]; kinematics::Quaternion as (p0, p1, p2, p3);
/// strings as they are; types with a Describer specialisation (bodies.hpp: RigidBody, State,
/// Loads); anything else with operator<<, and ranges of these as {a, b}.
template <class... Args>
std::string describe(const Args&... args) {
  static_assert(sizeof...(Args) % 2 == 0, "describe() takes name, value pairs");
  std::ostringstream os;
  detail::put_pairs(os, args...);
  return os.str();
}

/// The value alone, formatted as describe() formats it: e.g. format(P) = "(p0, p1, p2, p3)".
template <class T>
std::string format(const T& x) {
  std::ostringstream os;
  detail::put_value(os, x);
  return os.str();
}

}  // namespace grbd::test
