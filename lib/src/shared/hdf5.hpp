#pragma once
// The parts of HDF5's C API that every grbd reader and writer needs (private to the library, and
// of no module: lib/src/shared/ holds what several modules' implementations share — here chapter
// 5's FCLIB reader and chapter 7's output and checkpoints):
// handles closed by RAII, a switch for HDF5's own printing of its error stack, the innermost HDF5
// message for grbd's errors, and the mutex that serializes calls into an HDF5 that is not built
// thread-safe.

#include <hdf5.h>

#include <mutex>
#include <string>
#include <utility>

namespace grbd::hdf5 {

/// Serializes grbd's calls into HDF5 (and the error-printing switch below).
inline std::mutex& mutex() {
  static std::mutex instance;
  return instance;
}

/// Switches HDF5's automatic printing of the error stack off for its lifetime and restores the
/// previous handler afterwards.
class QuietErrors {
 public:
  QuietErrors() {
    H5Eget_auto2(H5E_DEFAULT, &function_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietErrors() { H5Eset_auto2(H5E_DEFAULT, function_, data_); }
  QuietErrors(const QuietErrors&) = delete;
  QuietErrors& operator=(const QuietErrors&) = delete;

 private:
  H5E_auto2_t function_ = nullptr;
  void* data_ = nullptr;
};

/// An HDF5 identifier (file, group, dataset, dataspace, datatype, property list) that is closed
/// when the Handle goes out of scope. A negative id is "no object".
class Handle {
 public:
  using Close = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Close close) : id_(id), close_(close) {}
  ~Handle() { reset(); }
  Handle(Handle&& other) noexcept
      : id_(std::exchange(other.id_, H5I_INVALID_HID)), close_(other.close_) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, H5I_INVALID_HID);
      close_ = other.close_;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  /// Closes now; returns false when HDF5 reports a failure (a write that could not be flushed).
  bool close() {
    const bool ok = id_ < 0 || close_ == nullptr || close_(id_) >= 0;
    id_ = H5I_INVALID_HID;
    return ok;
  }
  /// Forgets the object without closing it: what a collective file whose processes can no longer
  /// close it together needs (the object stays open until the process ends).
  void release() { id_ = H5I_INVALID_HID; }

 private:
  void reset() {
    if (id_ >= 0 && close_ != nullptr) close_(id_);
    id_ = H5I_INVALID_HID;
  }
  hid_t id_ = H5I_INVALID_HID;
  Close close_ = nullptr;
};

/// The description of the innermost error on HDF5's default error stack (where the failure was
/// detected), or "" if the stack is empty. Must be called right after the failing HDF5 call.
inline std::string message() {
  std::string text;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned n, const H5E_error2_t* error, void* data) -> herr_t {
        if (n == 0 && error != nullptr && error->desc != nullptr) {
          *static_cast<std::string*>(data) = error->desc;
        }
        return 0;
      },
      &text);
  return text.empty() ? std::string() : " (HDF5: " + text + ")";
}

}  // namespace grbd::hdf5
