// Reading typed values out of XmlRpc parameter trees, each failure an Error naming the key.
#pragma once

#include <XmlRpcValue.h>

#include <Eigen/Core>
#include <set>
#include <string>

#include "collision_response/core/expected.h"

namespace collision_response {

/// The parameter's full name for messages: "~scene/bodies[2]/mass".
std::string joinKey(const std::string& parent, const std::string& child);
std::string indexKey(const std::string& parent, std::size_t index);

/// Every key of a struct parameter must be in `known`; the first that is not is an error.
core::Status checkKeys(const XmlRpc::XmlRpcValue& value, const std::set<std::string>& known,
                       const std::string& field);
core::Status checkStruct(const XmlRpc::XmlRpcValue& value, const std::string& field);
core::Status checkArray(const XmlRpc::XmlRpcValue& value, const std::string& field);

/// An int or a double (YAML `1` and `1.0` alike; `.inf` is a double).
core::Expected<double> readDouble(const XmlRpc::XmlRpcValue& value, const std::string& field);
core::Expected<std::string> readString(const XmlRpc::XmlRpcValue& value, const std::string& field);
core::Expected<bool> readBool(const XmlRpc::XmlRpcValue& value, const std::string& field);
/// A list of three numbers.
core::Expected<Eigen::Vector3d> readVector3(const XmlRpc::XmlRpcValue& value,
                                            const std::string& field);

}  // namespace collision_response
