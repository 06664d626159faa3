#include "motion/kinematics.hpp"

#include <cctype>
#include <numbers>
#include <stdexcept>
#include <string>

namespace motion {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr std::string_view kAxisLetters = "XYZABCUVW";

Eigen::Matrix3d rot_x(double deg) {
    return Eigen::AngleAxisd(deg * kDegToRad, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
Eigen::Matrix3d rot_z(double deg) {
    return Eigen::AngleAxisd(deg * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

int axis_index(char letter) noexcept {
    auto pos =
        kAxisLetters.find(static_cast<char>(std::toupper(static_cast<unsigned char>(letter))));
    return pos == std::string_view::npos ? -1 : static_cast<int>(pos);
}

TrivialKinematics::TrivialKinematics(std::string_view coordinates) {
    if (coordinates.empty()) throw std::invalid_argument("coordinates= is empty");
    for (char c : coordinates) {
        int ax = axis_index(c);
        if (ax < 0)
            throw std::invalid_argument(std::string("coordinates=") + std::string(coordinates) +
                                        ": '" + c + "' is not an axis letter (XYZABCUVW)");
        axes_.push_back(ax);
    }
}

void TrivialKinematics::inverse(const AxisArray& axes, std::span<double> joints) const noexcept {
    for (std::size_t i = 0; i < axes_.size(); ++i) joints[i] = axes[axes_[i]];
}

void TrivialKinematics::forward(std::span<const double> joints, AxisArray& axes) const noexcept {
    // Walk backwards so that the first joint of a gantry pair wins.
    for (std::size_t i = axes_.size(); i-- > 0;) axes[axes_[i]] = joints[i];
}

std::vector<AxisArray> TrivialKinematics::linear_map() const {
    std::vector<AxisArray> rows(axes_.size(), AxisArray{});
    for (std::size_t i = 0; i < axes_.size(); ++i) rows[i][static_cast<std::size_t>(axes_[i])] = 1;
    return rows;
}

std::vector<AxisArray> CoreXYKinematics::linear_map() const {
    std::vector<AxisArray> rows(3, AxisArray{});
    rows[0][0] = 1, rows[0][1] = 1;   // X + Y
    rows[1][0] = 1, rows[1][1] = -1;  // X - Y
    rows[2][2] = 1;
    return rows;
}

void CoreXYKinematics::inverse(const AxisArray& axes, std::span<double> joints) const noexcept {
    joints[0] = axes[0] + axes[1];
    joints[1] = axes[0] - axes[1];
    joints[2] = axes[2];
}

void CoreXYKinematics::forward(std::span<const double> joints, AxisArray& axes) const noexcept {
    axes[0] = (joints[0] + joints[1]) / 2;
    axes[1] = (joints[0] - joints[1]) / 2;
    axes[2] = joints[2];
}

void XyzacTrtKinematics::inverse(const AxisArray& axes, std::span<double> joints) const noexcept {
    Eigen::Vector3d p(axes[0], axes[1], axes[2]);
    double a = axes[3], c = axes[5];
    Eigen::Vector3d m =
        rot_x(a) * (rot_z(c) * (p - pv_.c_pivot_mm) + pv_.c_pivot_mm - pv_.a_pivot_mm) +
        pv_.a_pivot_mm;
    joints[0] = m.x();
    joints[1] = m.y();
    joints[2] = m.z();
    joints[3] = a;
    joints[4] = c;
}

void XyzacTrtKinematics::forward(std::span<const double> joints, AxisArray& axes) const noexcept {
    Eigen::Vector3d m(joints[0], joints[1], joints[2]);
    double a = joints[3], c = joints[4];
    // Rotation inverses are transposes.
    Eigen::Vector3d p = rot_z(c).transpose() * (rot_x(a).transpose() * (m - pv_.a_pivot_mm) +
                                                pv_.a_pivot_mm - pv_.c_pivot_mm) +
                        pv_.c_pivot_mm;
    axes[0] = p.x();
    axes[1] = p.y();
    axes[2] = p.z();
    axes[3] = a;
    axes[5] = c;
}

std::unique_ptr<Kinematics> make_kinematics(std::string_view name, std::string_view coordinates,
                                            const TrtPivots& pivots) {
    if (name == "trivial") return std::make_unique<TrivialKinematics>(coordinates);
    if (name == "corexy") return std::make_unique<CoreXYKinematics>();
    if (name == "xyzac-trt") return std::make_unique<XyzacTrtKinematics>(pivots);
    throw std::invalid_argument("unknown kinematics '" + std::string(name) +
                                "' (known: trivial, corexy, xyzac-trt)");
}

}  // namespace motion
