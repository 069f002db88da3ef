// Unit dual quaternions, their blending, the weighted Kabsch rotation and the rigidity check.
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <string>

#include "dmc/tvm.h"

namespace dmc::tvm {

namespace {

Eigen::Quaterniond PureQuaternion(const Eigen::Vector3d& v) {
  return Eigen::Quaterniond(0.0, v.x(), v.y(), v.z());
}

Eigen::Quaterniond Add(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  Eigen::Quaterniond sum;
  sum.coeffs() = a.coeffs() + b.coeffs();
  return sum;
}

Eigen::Quaterniond Scale(const Eigen::Quaterniond& q, double s) {
  Eigen::Quaterniond scaled;
  scaled.coeffs() = q.coeffs() * s;
  return scaled;
}

}  // namespace

DualQuaternion DualQuaternion::FromRigid(const Eigen::Quaterniond& rotation,
                                         const Eigen::Vector3d& translation) {
  return {rotation, Scale(PureQuaternion(translation) * rotation, 0.5)};
}

DualQuaternion DualQuaternion::FromTranslation(const Eigen::Vector3d& translation) {
  return FromRigid(Eigen::Quaterniond::Identity(), translation);
}

DualQuaternion DualQuaternion::FromRotation(const Eigen::Quaterniond& rotation) {
  return {rotation, Eigen::Quaterniond(0.0, 0.0, 0.0, 0.0)};
}

DualQuaternion DualQuaternion::FromIsometry(const Eigen::Isometry3d& isometry) {
  Eigen::Quaterniond rotation(isometry.linear());
  rotation.normalize();
  return FromRigid(rotation, isometry.translation());
}

DualQuaternion DualQuaternion::operator*(const DualQuaternion& other) const {
  return {real_ * other.real_, Add(real_ * other.dual_, dual_ * other.real_)};
}

DualQuaternion DualQuaternion::operator+(const DualQuaternion& other) const {
  return {Add(real_, other.real_), Add(dual_, other.dual_)};
}

DualQuaternion DualQuaternion::operator*(double scale) const {
  return {Scale(real_, scale), Scale(dual_, scale)};
}

DualQuaternion DualQuaternion::Normalized() const {
  const double norm = real_.norm();
  const Eigen::Quaterniond real = Scale(real_, 1.0 / norm);
  Eigen::Quaterniond dual = Scale(dual_, 1.0 / norm);
  // A unit dual quaternion has r . d = 0; remove the component that blending introduced.
  dual.coeffs() -= real.coeffs().dot(dual.coeffs()) * real.coeffs();
  return {real, dual};
}

Eigen::Vector3d DualQuaternion::Translation() const {
  return 2.0 * (dual_ * real_.conjugate()).vec();
}

Eigen::Isometry3d DualQuaternion::ToIsometry() const {
  Eigen::Isometry3d isometry = Eigen::Isometry3d::Identity();
  isometry.linear() = real_.toRotationMatrix();
  isometry.translation() = Translation();
  return isometry;
}

double DualQuaternion::RotationAngle() const {
  const double w = std::min(1.0, std::abs(real_.w()) / real_.norm());
  return 2.0 * std::acos(w);
}

Eigen::Vector3d DualQuaternion::Apply(const Eigen::Vector3d& point) const {
  return real_ * point + Translation();
}

DualQuaternion BlendDualQuaternions(std::span<const DualQuaternion> transforms,
                                    std::span<const double> weights) {
  const DualQuaternion* pivot = nullptr;
  DualQuaternion sum({0.0, 0.0, 0.0, 0.0}, {0.0, 0.0, 0.0, 0.0});
  for (size_t i = 0; i < transforms.size(); ++i) {
    if (weights[i] == 0.0) continue;
    if (pivot == nullptr) pivot = &transforms[i];
    // q and -q are the same motion; blending them with opposite signs would cancel.
    const double sign = transforms[i].RealDot(*pivot) < 0.0 ? -1.0 : 1.0;
    sum = sum + transforms[i] * (sign * weights[i]);
  }
  if (pivot == nullptr || sum.Norm() == 0.0) return DualQuaternion::Identity();
  return sum.Normalized();
}

Eigen::Matrix3d WeightedKabsch(const Eigen::Ref<const FramePositionsD>& source,
                               const Eigen::Ref<const FramePositionsD>& target,
                               std::span<const double> weights) {
  double total = 0.0;
  Eigen::RowVector3d source_centroid = Eigen::RowVector3d::Zero();
  Eigen::RowVector3d target_centroid = Eigen::RowVector3d::Zero();
  for (size_t j = 0; j < weights.size(); ++j) {
    const auto row = static_cast<Eigen::Index>(j);
    total += weights[j];
    source_centroid += weights[j] * source.row(row);
    target_centroid += weights[j] * target.row(row);
  }
  if (total <= 0.0) return Eigen::Matrix3d::Identity();
  source_centroid /= total;
  target_centroid /= total;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (size_t j = 0; j < weights.size(); ++j) {
    const auto row = static_cast<Eigen::Index>(j);
    covariance += weights[j] * (source.row(row) - source_centroid).transpose() *
                  (target.row(row) - target_centroid);
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  // A neighbourhood collapsed to a point carries no orientation: keep the identity.
  if (svd.singularValues()[0] <= 1e-300) return Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d& u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  Eigen::Matrix3d correction = Eigen::Matrix3d::Identity();
  correction(2, 2) = (v * u.transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return v * correction * u.transpose();
}

Status CheckRigid(const Eigen::Isometry3d& transform, std::string_view what) {
  if (!transform.matrix().allFinite()) {
    return InvalidArgumentError(std::string(what) + " has a non-finite entry");
  }
  const Eigen::Matrix3d linear = transform.linear();
  const double orthogonality = (linear * linear.transpose() - Eigen::Matrix3d::Identity()).norm();
  if (orthogonality > 1e-6 || linear.determinant() < 0.0) {
    return InvalidArgumentError(std::string(what) +
                                " is not rigid: its 3x3 part must be a rotation (orthonormal, "
                                "determinant +1)");
  }
  return Status::Ok();
}

}  // namespace dmc::tvm
