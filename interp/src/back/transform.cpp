#include "interp/transform.hpp"

#include <cmath>
#include <numbers>

namespace interp {

Eigen::Affine3d rotation_about(Plane plane, const Eigen::Vector3d& centre_mm, double angle_deg) {
    const PlaneAxes ax = plane_axes(plane);
    Eigen::Vector3d axis = Eigen::Vector3d::Zero();
    axis[ax.normal] = 1.0;
    const double rad = angle_deg * std::numbers::pi / 180.0;
    Eigen::Affine3d m = Eigen::Translation3d(centre_mm) * Eigen::AngleAxisd(rad, axis) *
                        Eigen::Translation3d(-centre_mm);
    return m;
}

bool ProgramTransform::has(Kind k) const {
    for (const Entry& e : entries_)
        if (e.kind == k) return true;
    return false;
}

bool ProgramTransform::push(const Entry& e) {
    if (!entries_.push_back(e)) return false;
    total_ = total_ * e.m;
    return true;
}

void ProgramTransform::recompute() {
    total_ = Eigen::Affine3d::Identity();
    for (const Entry& e : entries_) total_ = total_ * e.m;
}

bool ProgramTransform::push_rotation(Plane plane, const Eigen::Vector3d& centre_mm,
                                     double angle_deg) {
    return push(Entry{Kind::Rotation, rotation_about(plane, centre_mm, angle_deg), 0, centre_mm});
}

bool ProgramTransform::push_scale(const Eigen::Vector3d& centre_mm,
                                  const Eigen::Vector3d& factors) {
    Eigen::Affine3d m = Eigen::Translation3d(centre_mm) * Eigen::Scaling(factors) *
                        Eigen::Translation3d(-centre_mm);
    return push(Entry{Kind::Scale, m, 0, centre_mm});
}

namespace {
Eigen::Affine3d mirror_matrix(const Eigen::Vector3d& centre, unsigned mask) {
    Eigen::Vector3d f(1, 1, 1);
    for (int i = 0; i < 3; ++i)
        if (mask & (1u << i)) f[i] = -1;
    return Eigen::Translation3d(centre) * Eigen::Scaling(f) * Eigen::Translation3d(-centre);
}
}  // namespace

bool ProgramTransform::push_mirror(const Eigen::Vector3d& centre_mm, unsigned axis_mask) {
    return push(Entry{Kind::Mirror, mirror_matrix(centre_mm, axis_mask), axis_mask, centre_mm});
}

bool ProgramTransform::pop_rotation() {
    for (std::size_t i = entries_.size(); i-- > 0;) {
        if (entries_[i].kind == Kind::Rotation) {
            entries_.erase_at(i);
            recompute();
            return true;
        }
    }
    return false;
}

void ProgramTransform::clear_scaling() {
    for (std::size_t i = 0; i < entries_.size();) {
        if (entries_[i].kind == Kind::Scale)
            entries_.erase_at(i);
        else
            ++i;
    }
    recompute();
}

void ProgramTransform::clear_mirror(unsigned axis_mask) {
    for (std::size_t i = 0; i < entries_.size();) {
        Entry& e = entries_[i];
        if (e.kind == Kind::Mirror) {
            e.mirror_mask &= ~axis_mask;
            if (e.mirror_mask == 0) {
                entries_.erase_at(i);
                continue;
            }
            e.m = mirror_matrix(e.centre, e.mirror_mask);
        }
        ++i;
    }
    recompute();
}

}  // namespace interp
