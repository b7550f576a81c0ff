#pragma once
// Conversions between the wire types of rrg.v1 (proto/rrg/v1/service.proto) and core's types,
// shared by the server and the client library. Checks throw std::invalid_argument naming the field.
#include "core/common/camera.h"
#include "core/tracking/tracker.h"
#include "rrg/v1/service.pb.h"

#include <Eigen/Geometry>

#include <string>

namespace rrg::service {

v1::Pose to_proto(const Eigen::Isometry3f& T);
v1::Pose to_proto(const Eigen::Isometry3d& T);
// Throws std::invalid_argument("<field>: ...") for a non-finite value or a zero quaternion.
Eigen::Isometry3f from_proto(const v1::Pose& p, const std::string& field = "pose");

v1::CameraIntrinsics to_proto(const Intrinsics& K);
Intrinsics from_proto(const v1::CameraIntrinsics& K);  // no checks (io::validate_intrinsics does them)

v1::TrackingState to_proto(TrackingState s);
std::string to_string(v1::TrackingState s);

}  // namespace rrg::service
