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

/// Number checks used by the parameter tables.
core::Status checkPositive(double value, const std::string& field);     ///< finite, > 0
core::Status checkNonNegative(double value, const std::string& field);  ///< finite, >= 0

}  // namespace collision_response
