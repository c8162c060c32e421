#include "collision_response/ros/parameters.h"

#include <cmath>

#include "collision_response/core/validation.h"

namespace collision_response {

const char* typeName(const XmlRpc::XmlRpcValue& value) {
  switch (value.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return "a boolean";
    case XmlRpc::XmlRpcValue::TypeInt:
      return "an integer";
    case XmlRpc::XmlRpcValue::TypeDouble:
      return "a number";
    case XmlRpc::XmlRpcValue::TypeString:
      return "a string";
    case XmlRpc::XmlRpcValue::TypeArray:
      return "a list";
    case XmlRpc::XmlRpcValue::TypeStruct:
      return "a mapping";
    default:
      return "another type";
  }
}

namespace {

/// What the value was, for a message: its type, and a scalar's text.
std::string describe(const XmlRpc::XmlRpcValue& value) {
  XmlRpc::XmlRpcValue copy = value;
  switch (copy.getType()) {
    case XmlRpc::XmlRpcValue::TypeString: {
      const std::string text = copy;
      return std::string("a string ('") + (text.size() > 40 ? text.substr(0, 40) + "..." : text) +
             "')";
    }
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return std::string("a boolean (") + (static_cast<bool>(copy) ? "true" : "false") + ")";
    case XmlRpc::XmlRpcValue::TypeInt:
      return "an integer (" + std::to_string(static_cast<int>(copy)) + ")";
    case XmlRpc::XmlRpcValue::TypeDouble:
      return "a number (" + core::formatNumber(static_cast<double>(copy)) + ")";
    case XmlRpc::XmlRpcValue::TypeArray:
      return "a list of " + std::to_string(copy.size());
    default:
      return typeName(value);
  }
}

core::Error wrongType(const XmlRpc::XmlRpcValue& value, const std::string& field,
                      const std::string& expected) {
  return core::Error{field, "must be " + expected + ", got " + describe(value)};
}

}  // namespace

std::string joinKey(const std::string& parent, const std::string& child) {
  return parent.empty() ? child : parent + "/" + child;
}

std::string indexKey(const std::string& parent, std::size_t index) {
  return parent + "[" + std::to_string(index) + "]";
}

core::Status checkStruct(const XmlRpc::XmlRpcValue& value, const std::string& field) {
  if (value.getType() != XmlRpc::XmlRpcValue::TypeStruct)
    return wrongType(value, field, "a mapping");
  return core::Ok{};
}

core::Status checkArray(const XmlRpc::XmlRpcValue& value, const std::string& field) {
  if (value.getType() != XmlRpc::XmlRpcValue::TypeArray) return wrongType(value, field, "a list");
  return core::Ok{};
}

core::Error unknownKey(const std::string& field, const std::vector<std::string>& known) {
  std::string list;
  for (const std::string& key : known) list += (list.empty() ? "" : ", ") + key;
  return core::Error{field, "unknown key; known here: " + list};
}

core::Expected<double> readDouble(const XmlRpc::XmlRpcValue& value, const std::string& field) {
  // XmlRpcValue's conversion operators are not const; copy to read.
  XmlRpc::XmlRpcValue copy = value;
  if (copy.getType() == XmlRpc::XmlRpcValue::TypeDouble) return static_cast<double>(copy);
  if (copy.getType() == XmlRpc::XmlRpcValue::TypeInt)
    return static_cast<double>(static_cast<int>(copy));
  return wrongType(value, field, "a number");
}

core::Expected<int> readInt(const XmlRpc::XmlRpcValue& value, const std::string& field) {
  XmlRpc::XmlRpcValue copy = value;
  if (copy.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(copy);
  return wrongType(value, field, "an integer");
}

core::Expected<std::string> readString(const XmlRpc::XmlRpcValue& value, const std::string& field) {
  XmlRpc::XmlRpcValue copy = value;
  if (copy.getType() == XmlRpc::XmlRpcValue::TypeString) return static_cast<std::string>(copy);
  return wrongType(value, field, "a string");
}

core::Expected<bool> readBool(const XmlRpc::XmlRpcValue& value, const std::string& field) {
  XmlRpc::XmlRpcValue copy = value;
  if (copy.getType() == XmlRpc::XmlRpcValue::TypeBoolean) return static_cast<bool>(copy);
  return wrongType(value, field, "true or false");
}

core::Expected<Eigen::Vector3d> readVector3(const XmlRpc::XmlRpcValue& value,
                                            const std::string& field) {
  if (value.getType() != XmlRpc::XmlRpcValue::TypeArray || value.size() != 3) {
    return core::Error{field, "must be a list of three numbers [x, y, z]"};
  }
  Eigen::Vector3d result;
  for (int i = 0; i < 3; ++i) {
    const auto component = readDouble(value[i], indexKey(field, static_cast<std::size_t>(i)));
    if (!component) return component.error();
    result[i] = *component;
  }
  return result;
}

core::Status checkPositive(double value, const std::string& field) {
  if (!std::isfinite(value) || !(value > 0.0)) {
    return core::Error{field, "must be a finite number > 0, got " + core::formatNumber(value)};
  }
  return core::Ok{};
}

core::Status checkNonNegative(double value, const std::string& field) {
  if (!std::isfinite(value) || value < 0.0) {
    return core::Error{field, "must be a finite number >= 0, got " + core::formatNumber(value)};
  }
  return core::Ok{};
}

namespace {

/// A duration's bounds, for `seconds` finite and > 0.
core::Status checkDurationRange(double seconds, const std::string& field) {
  if (seconds > kMaxDurationSeconds) {
    return core::Error{field, core::formatNumber(seconds) +
                                  " s is longer than a ros::Duration can hold (" +
                                  core::formatNumber(kMaxDurationSeconds) + " s)"};
  }
  if (seconds < kMinDurationSeconds) {
    return core::Error{field, core::formatNumber(seconds) +
                                  " s is shorter than a ros::Duration can hold (" +
                                  core::formatNumber(kMinDurationSeconds) + " s, one nanosecond)"};
  }
  return core::Ok{};
}

}  // namespace

core::Status checkDuration(double seconds, const std::string& field) {
  if (!std::isfinite(seconds) || !(seconds > 0.0)) {
    return core::Error{
        field, "must be a finite number of seconds > 0, got " + core::formatNumber(seconds)};
  }
  return checkDurationRange(seconds, field);
}

core::Status checkDurationOrZero(double seconds, const std::string& field) {
  if (!std::isfinite(seconds) || seconds < 0.0) {
    return core::Error{
        field, "must be a finite number of seconds >= 0, got " + core::formatNumber(seconds)};
  }
  return seconds == 0.0 ? core::Status(core::Ok{}) : checkDurationRange(seconds, field);
}

core::Status checkRate(double hertz, const std::string& field) {
  if (!std::isfinite(hertz) || !(hertz > 0.0)) {
    return core::Error{field,
                       "must be a finite number of Hz > 0, got " + core::formatNumber(hertz)};
  }
  const double period = 1.0 / hertz;
  if (period > kMaxDurationSeconds) {
    return core::Error{field, core::formatNumber(hertz) + " Hz is too slow: its period, " +
                                  core::formatNumber(period) +
                                  " s, is longer than a ros::Duration can hold (" +
                                  core::formatNumber(kMaxDurationSeconds) + " s)"};
  }
  if (period < kMinDurationSeconds) {
    return core::Error{field, core::formatNumber(hertz) + " Hz is too fast: its period, " +
                                  core::formatNumber(period) +
                                  " s, is shorter than a ros::Duration can hold (" +
                                  core::formatNumber(kMinDurationSeconds) + " s, one nanosecond)"};
  }
  return core::Ok{};
}

}  // namespace collision_response
