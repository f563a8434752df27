#pragma once
/// \file
/// \brief The exception types of grbd.
///
/// Every error a user can cause (bad input, an ill-posed problem, a solver that failed) is a
/// grbd::Error. grbd::NotImplemented is deliberately *not* a grbd::Error: it signals a missing
/// exercise, a property of the build rather than of the input, and a test that expects a
/// grbd::Error must never pass merely because the function under test is still a stub.

#include <stdexcept>
#include <string>
#include <string_view>

namespace grbd {

/// Base class of every error caused by input or by a failed computation.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Invalid arguments: a precondition of a library function is violated (for example a zero
/// quaternion where a rotation is expected).
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

/// Thrown by the stub of an exercise that the student has not written yet.
///
/// The message always starts with the tag `[NotImplemented]`, which the grading script and the
/// exercise honesty test use to tell "not implemented" apart from a wrong answer.
class NotImplemented : public std::logic_error {
 public:
  /// \param exercise e.g. "Exercise 1.3"
  /// \param title    what the exercise computes, e.g. "the rotation matrix R(p)"
  /// \param chapter  e.g. "Chapter 1: Quaternions and rigid kinematics"
  /// \param file     the exercise file to edit, relative to the repository root
  NotImplemented(std::string_view exercise, std::string_view title, std::string_view chapter,
                 std::string_view file);

  /// The exercise identifier, e.g. "Exercise 1.3".
  const std::string& exercise() const noexcept { return exercise_; }

 private:
  std::string exercise_;
};

}  // namespace grbd
