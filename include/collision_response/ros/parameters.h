// Typed reads of parameter trees (XmlRpc values, as rosparam loads them from YAML), and the key
// tables that read and check a struct: one table per entity lists its keys, and the same table
// both reads them and refuses the keys it does not list. Every failure is an Error naming the
// key's full name ("~scene/bodies[2]/mass") and the reason.
#pragma once

#include <XmlRpcValue.h>

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"

namespace collision_response {

/// The parameter's full name for messages: "~scene/bodies[2]/mass".
std::string joinKey(const std::string& parent, const std::string& child);
std::string indexKey(const std::string& parent, std::size_t index);

/// "a number", "a string", ...: what a value is, for messages.
const char* typeName(const XmlRpc::XmlRpcValue& value);

core::Status checkStruct(const XmlRpc::XmlRpcValue& value, const std::string& field);
core::Status checkArray(const XmlRpc::XmlRpcValue& value, const std::string& field);

/// An int or a double (YAML `1` and `1.0` alike; `.inf` is a double).
core::Expected<double> readDouble(const XmlRpc::XmlRpcValue& value, const std::string& field);
/// An int (YAML `3`); `3.0`, `true` or `"3"` are errors.
core::Expected<int> readInt(const XmlRpc::XmlRpcValue& value, const std::string& field);
core::Expected<std::string> readString(const XmlRpc::XmlRpcValue& value, const std::string& field);
core::Expected<bool> readBool(const XmlRpc::XmlRpcValue& value, const std::string& field);
/// A list of three numbers.
core::Expected<Eigen::Vector3d> readVector3(const XmlRpc::XmlRpcValue& value,
                                            const std::string& field);

/// One key of a mapping: its name, whether it must be present, and how its value is read into
/// the target (type and range checked; errors name `field`, the key's full name).
template <class Target>
struct Key {
  std::string name;
  bool required = false;
  std::function<core::Status(const XmlRpc::XmlRpcValue& value, const std::string& field,
                             Target& target)>
      read;
};
template <class Target>
using KeyTable = std::vector<Key<Target>>;

/// The names of a table's keys, in its order.
template <class Target>
std::vector<std::string> keyNames(const KeyTable<Target>& keys) {
  std::vector<std::string> names;
  for (const Key<Target>& key : keys) names.push_back(key.name);
  return names;
}

/// An error for a key no table lists, with the keys that are known there.
core::Error unknownKey(const std::string& field, const std::vector<std::string>& known);

/// Reads the mapping `value` into `target` with `keys`, in the table's order: a key the table
/// does not list, a required key that is missing, or a value its reader refuses is an error
/// naming the key (`field`/key).
template <class Target>
core::Status readKeys(const XmlRpc::XmlRpcValue& value, const KeyTable<Target>& keys,
                      const std::string& field, Target& target) {
  if (auto status = checkStruct(value, field); !status) return status;
  for (auto it = value.begin(); it != value.end(); ++it) {
    bool listed = false;
    for (const Key<Target>& key : keys) listed = listed || key.name == it->first;
    if (!listed) return unknownKey(joinKey(field, it->first), keyNames(keys));
  }
  for (const Key<Target>& key : keys) {
    const std::string key_field = joinKey(field, key.name);
    if (!value.hasMember(key.name)) {
      if (key.required) return core::Error{key_field, "is required"};
      continue;
    }
    if (auto status = key.read(value[key.name], key_field, target); !status) return status;
  }
  return core::Ok{};
}

/// A range check of a number, naming the field: core::checkMass, core::checkRadius, ...
using NumberCheck = std::function<core::Status(double value, const std::string& field)>;
using TextCheck = std::function<core::Status(const std::string& value, const std::string& field)>;

/// Keys of the common kinds. `member` returns the target's field to set.
template <class Target>
Key<Target> numberKey(const std::string& name, std::function<double&(Target&)> member,
                      NumberCheck check = nullptr, bool required = false) {
  return {name, required,
          [member, check](const XmlRpc::XmlRpcValue& value, const std::string& field,
                          Target& target) -> core::Status {
            const auto number = readDouble(value, field);
            if (!number) return number.error();
            if (check) {
              if (auto status = check(*number, field); !status) return status;
            }
            member(target) = *number;
            return core::Ok{};
          }};
}

/// An integer >= `minimum`.
template <class Target>
Key<Target> countKey(const std::string& name, std::function<int&(Target&)> member, int minimum) {
  return {name, false,
          [member, minimum](const XmlRpc::XmlRpcValue& value, const std::string& field,
                            Target& target) -> core::Status {
            const auto count = readInt(value, field);
            if (!count) return count.error();
            if (*count < minimum) {
              return core::Error{field, "must be an integer >= " + std::to_string(minimum) +
                                            ", got " + std::to_string(*count)};
            }
            member(target) = *count;
            return core::Ok{};
          }};
}

template <class Target>
Key<Target> boolKey(const std::string& name, std::function<bool&(Target&)> member) {
  return {name, false,
          [member](const XmlRpc::XmlRpcValue& value, const std::string& field,
                   Target& target) -> core::Status {
            const auto flag = readBool(value, field);
            if (!flag) return flag.error();
            member(target) = *flag;
            return core::Ok{};
          }};
}

template <class Target>
Key<Target> textKey(const std::string& name, std::function<std::string&(Target&)> member,
                    TextCheck check = nullptr, bool required = false) {
  return {name, required,
          [member, check](const XmlRpc::XmlRpcValue& value, const std::string& field,
                          Target& target) -> core::Status {
            const auto text = readString(value, field);
            if (!text) return text.error();
            if (check) {
              if (auto status = check(*text, field); !status) return status;
            }
            member(target) = *text;
            return core::Ok{};
          }};
}

template <class Target>
Key<Target> vectorKey(const std::string& name, std::function<Eigen::Vector3d&(Target&)> member,
                      bool required = false) {
  return {name, required,
          [member](const XmlRpc::XmlRpcValue& value, const std::string& field,
                   Target& target) -> core::Status {
            const auto vector = readVector3(value, field);
            if (!vector) return vector.error();
            member(target) = *vector;
            return core::Ok{};
          }};
}

/// Reads the one key `name` of `keys` from `value` into `target`, as readKeys reads it (the same
/// reader, the same checks): how a parameter re-read while the node runs is checked exactly as at
/// start-up. `field` is the key's full name.
template <class Target>
core::Status readKey(const XmlRpc::XmlRpcValue& value, const KeyTable<Target>& keys,
                     const std::string& name, const std::string& field, Target& target) {
  for (const Key<Target>& key : keys) {
    if (key.name == name) return key.read(value, field, target);
  }
  return unknownKey(field, keyNames(keys));
}

/// Number checks used by the parameter tables.
core::Status checkPositive(double value, const std::string& field);     ///< finite, > 0
core::Status checkNonNegative(double value, const std::string& field);  ///< finite, >= 0

/// The longest time a ros::Duration holds, s: its seconds are an int32 (ros::Duration(1e10)
/// throws "Duration is out of dual 32-bit range"). Durations up to it also fit a ros::Time's
/// range from 0 and, in nanoseconds, an int64.
inline constexpr double kMaxDurationSeconds = 2147483647.0;
/// The shortest nonzero time a ros::Duration holds, s: one nanosecond (shorter rounds to 0).
inline constexpr double kMinDurationSeconds = 1e-9;

/// Every parameter that is a time span (a ros::Duration, a timer's period, a limit compared with
/// one): finite, > 0, at least kMinDurationSeconds and at most kMaxDurationSeconds.
core::Status checkDuration(double seconds, const std::string& field);
/// As checkDuration, or 0.
core::Status checkDurationOrZero(double seconds, const std::string& field);
/// A rate, Hz: finite, > 0, and its period 1/rate a duration (checkDuration).
core::Status checkRate(double hertz, const std::string& field);

}  // namespace collision_response
