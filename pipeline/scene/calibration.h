// Site calibration from measurements a technician can take: the tracker's pose in the booth
// (T_booth_tracker, a least-squares rigid fit of tracker readings of a marker held at known booth
// points) and the stand's geometry (hinge axis from accelerometer readings at several tilts, hinge
// position and panel offset from tape-measured positions of the panel's top edge).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/base/rigid_transform.h>
#include <pipeline/scene/stand.h>

namespace replica::pipeline::scene {

struct RigidFitOptions {
    double maxRmsM = 0.010;   // refuse a fit whose RMS residual is larger (points were wrong)
    double minSpreadM = 0.05; // refuse points within this RMS distance of one line (collinear)
};

struct RigidFit {
    RigidTransform T_booth_tracker; // p_booth = rotation * p_tracker + translation
    std::vector<double> residualsM; // |T p_tracker - p_booth| per point
    double rmsM = 0.0;
    std::size_t worst = 0; // index of the largest residual
    double spreadM = 0.0;  // RMS distance of the booth points from their best-fit line
};

// Kabsch (SVD of the cross-covariance, the determinant's sign fixed so the result is a rotation,
// never a reflection). Fails for fewer than three points, non-finite values, (nearly) collinear
// points, or an RMS residual above options.maxRmsM, naming the worst point (1-based).
Expected<RigidFit> fitRigid(std::span<const glm::dvec3> trackerM,
                            std::span<const glm::dvec3> boothM,
                            const RigidFitOptions& options = {});

// Eigen-decomposition of a symmetric 3x3 matrix (cyclic Jacobi): eigenvalues in descending order,
// eigenvectors as the matching columns.
void symmetricEigen(const glm::dmat3& a, glm::dvec3& values, glm::dmat3& vectors);

// One stand measurement: the accelerometer's gravity (panel axes, as the loop sees it, m/s^2) and
// the tape-measured booth position of the middle of the panel's top edge (y height above the
// booth floor, z towards the viewer from the booth's centre, metres).
struct StandReading {
    glm::dvec3 gravityPanel{0.0};
    double topHeightM = 0.0;
    double topDepthM = 0.0;
};

struct StandFitOptions {
    double maxRmsM = 0.010;         // refuse when the tape and the tilts disagree by more
    double minTiltSpreadRad = 0.09; // about 5 degrees between the extreme tilts
};

struct StandFit {
    StandModel stand;
    glm::dvec3 hingeAxisPanel{1.0, 0.0, 0.0}; // measured, unit, x >= 0
    double axisAngleRad = 0.0; // between the measured hinge axis and the panel's x axis
    std::vector<double> tiltsRad;
    double rmsM = 0.0; // of the tape positions against the fitted hinge model
};

// panelWidthM/panelHeightM: the active area, tape-measured. Needs two or more readings at tilts at
// least minTiltSpreadRad apart.
Expected<StandFit> fitStand(std::span<const StandReading> readings,
                            double panelWidthM,
                            double panelHeightM,
                            const StandFitOptions& options = {});

} // namespace replica::pipeline::scene
