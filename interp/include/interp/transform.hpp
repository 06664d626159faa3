#pragma once
// Programmed coordinate transforms of NcStudio: G68 rotations, G51 scaling and G51.1 mirroring,
// composed in the order they were programmed (FEATURES SCL-10, ROT-3, CS-1).
//
// A point p written in the program maps to work coordinates as  T1 · T2 · … · Tn · p, where T1
// was programmed first. So each new transform acts inside the frame the earlier ones produced:
// its centre is written in that frame, exactly as the manual's nested-rotation example shows.
// G69 removes the most recently programmed rotation, G50 every scaling, G50.1 the mirroring of
// the axes it names; the others keep their place in the chain.
//
// Lengths in mm, angles in degrees. Only X, Y, Z take part; rotary axes pass through.
#include <Eigen/Geometry>
#include <array>
#include <cstddef>

#include "interp/canon.hpp"
#include "interp/static_vec.hpp"

namespace interp {

class ProgramTransform {
  public:
    // At least the 8 nested rotations FEATURES ROT-3 asks for, plus scaling and mirroring, and
    // room for the manual's "rotate and scale ten times" example.
    static constexpr std::size_t kMaxEntries = 32;

    enum class Kind { Rotation, Scale, Mirror };

    // False when the chain is full.
    bool push_rotation(Plane plane, const Eigen::Vector3d& centre_mm, double angle_deg);
    bool push_scale(const Eigen::Vector3d& centre_mm, const Eigen::Vector3d& factors);
    // Mirrors the axes in mask (bit 0 = X) about the centre's coordinates on those axes.
    bool push_mirror(const Eigen::Vector3d& centre_mm, unsigned axis_mask);
    // G69: false when no rotation is active.
    bool pop_rotation();
    void clear_scaling();
    // G50.1: the listed axes are no longer mirrored by any entry.
    void clear_mirror(unsigned axis_mask);
    void clear() {
        entries_.clear();
        total_ = Eigen::Affine3d::Identity();
    }

    bool identity() const { return entries_.empty(); }
    bool scaling_active() const { return has(Kind::Scale); }
    bool mirror_active() const { return has(Kind::Mirror); }
    bool rotation_active() const { return has(Kind::Rotation); }
    std::size_t size() const { return entries_.size(); }

    const Eigen::Affine3d& matrix() const { return total_; }
    Eigen::Vector3d apply(const Eigen::Vector3d& p) const { return total_ * p; }
    Eigen::Vector3d inverse(const Eigen::Vector3d& p) const { return total_.inverse() * p; }

  private:
    struct Entry {
        Kind kind;
        Eigen::Affine3d m;
        unsigned mirror_mask;    // Mirror only
        Eigen::Vector3d centre;  // Mirror only
    };
    bool has(Kind k) const;
    bool push(const Entry& e);
    void recompute();

    StaticVec<Entry, kMaxEntries> entries_;
    Eigen::Affine3d total_ = Eigen::Affine3d::Identity();
};

// The rotation about `centre` by `angle_deg` in `plane` (counter-clockwise seen from the positive
// normal axis), as a standalone matrix; exposed for tests.
Eigen::Affine3d rotation_about(Plane plane, const Eigen::Vector3d& centre_mm, double angle_deg);

}  // namespace interp
