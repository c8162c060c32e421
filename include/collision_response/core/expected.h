// A value or a named error: how the core reports bad input without exceptions.
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace collision_response::core {

/// Why an input was refused: the field it concerns and the reason, in words.
struct Error {
  std::string field;   ///< the input that is wrong, as a user names it, e.g. "a.mass"
  std::string reason;  ///< why, e.g. "must be > 0 or .inf (immovable), got -1"

  /// "field: reason", the text services put in their `message`.
  std::string message() const { return field + ": " + reason; }
};

/// Either a T or an Error (C++17 has no std::expected).
template <typename T>
class Expected {
 public:
  Expected(T value) : storage_(std::move(value)) {}      // NOLINT: implicit by design
  Expected(Error error) : storage_(std::move(error)) {}  // NOLINT: implicit by design

  bool ok() const { return std::holds_alternative<T>(storage_); }
  explicit operator bool() const { return ok(); }

  const T& value() const { return std::get<T>(storage_); }
  T& value() { return std::get<T>(storage_); }
  const T& operator*() const { return value(); }
  const T* operator->() const { return &value(); }
  const Error& error() const { return std::get<Error>(storage_); }

 private:
  std::variant<T, Error> storage_;
};

/// For checks that return nothing on success.
struct Ok {};
using Status = Expected<Ok>;

}  // namespace collision_response::core
