/// @file
/// The one exception type for bad input. It names the object ("body 'crate'",
/// "joint 'hinge1'", "solver") and the field ("mass", "shapes[1].radius"), so
/// the command line can print one line that says exactly what to fix.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>

namespace cairn {
/// Bad input: names the object and the field.
class InputError : public std::runtime_error {
 public:
  /// Bad input in one field of one object.
  /// @param object  the object at fault, e.g. "body 'crate'"; may be empty
  /// @param field   which field of it, e.g. "shapes[1].radius"; may be empty
  /// @param message what is wrong with it
  InputError(std::string object, std::string field, const std::string& message)
      : std::runtime_error(compose(object, field, message)),
        object_(std::move(object)),
        field_(std::move(field)),
        message_(message) {}

  const std::string& object() const { return object_; }  ///< e.g. "body 'crate'"
  const std::string& field() const { return field_; }  ///< e.g. "shapes[1].radius"; may be empty
  const std::string& message() const { return message_; }  ///< what is wrong, without object and field

  /// The one-line message what() returns: "object: field 'field': message",
  /// leaving out the parts that are empty.
  /// @param object  as for the constructor
  /// @param field   as for the constructor
  /// @param message as for the constructor
  static std::string compose(const std::string& object, const std::string& field,
                             const std::string& message) {
    std::string s;
    if (!object.empty()) s += object;
    if (!field.empty()) s += (s.empty() ? "field '" : ": field '") + field + "'";
    return s.empty() ? message : s + ": " + message;
  }

 private:
  std::string object_, field_, message_;
};

/// A handle that names nothing in this world: its object was destroyed (a
/// stale handle: the slot's generation moved on) or it never existed here.
class HandleError : public InputError {
 public:
  HandleError(std::string object, const std::string& message) : InputError(std::move(object), "", message) {}  ///< the object named and why the handle is refused
};

/// A step that produced a non-finite state: names the body and the stage.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace cairn
