// Rigid fit (Kabsch) and stand fit.
#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include <pipeline/scene/calibration.h>

namespace replica::pipeline::scene {
namespace {

bool finite(const glm::dvec3& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

glm::dvec3 mean(std::span<const glm::dvec3> p)
{
    glm::dvec3 m(0.0);
    for (const auto& x : p) {
        m += x;
    }
    return m / static_cast<double>(p.size());
}

// RMS distance of points from their best-fit line: sqrt of the two smaller eigenvalues of their
// covariance.
double lineSpread(std::span<const glm::dvec3> p)
{
    const glm::dvec3 c = mean(p);
    glm::dmat3 cov(0.0);
    for (const auto& x : p) {
        const glm::dvec3 d = x - c;
        cov += glm::outerProduct(d, d);
    }
    cov /= static_cast<double>(p.size());
    glm::dvec3 values;
    glm::dmat3 vectors;
    symmetricEigen(cov, values, vectors);
    return std::sqrt(std::max(values[1] + values[2], 0.0));
}

} // namespace

void symmetricEigen(const glm::dmat3& m, glm::dvec3& values, glm::dmat3& vectors)
{
    // a[row][col]; glm is column-major (m[col][row]).
    std::array<std::array<double, 3>, 3> a{};
    std::array<std::array<double, 3>, 3> v{};
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
            a[r][c] = 0.5 * (m[c][r] + m[r][c]);
            v[r][c] = r == c ? 1.0 : 0.0;
        }
    }
    for (int sweep = 0; sweep < 64; ++sweep) {
        const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if (off <= 1e-30 * diag || off == 0.0) {
            break;
        }
        for (int p = 0; p < 2; ++p) {
            for (int q = p + 1; q < 3; ++q) {
                if (a[p][q] == 0.0) {
                    continue;
                }
                // Rotation P (P_pp = P_qq = c, P_pq = s, P_qp = -s) with (P^T A P)_pq = 0.
                const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                const double t = (theta >= 0.0 ? 1.0 : -1.0) /
                                 (std::abs(theta) + std::sqrt(theta * theta + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0);
                const double s = t * c;
                std::array<std::array<double, 3>, 3> rot{};
                for (int i = 0; i < 3; ++i) {
                    rot[i][i] = 1.0;
                }
                rot[p][p] = c;
                rot[q][q] = c;
                rot[p][q] = s;
                rot[q][p] = -s;
                std::array<std::array<double, 3>, 3> ap{};
                std::array<std::array<double, 3>, 3> vp{};
                for (int i = 0; i < 3; ++i) {
                    for (int j = 0; j < 3; ++j) {
                        for (int k = 0; k < 3; ++k) {
                            ap[i][j] += a[i][k] * rot[k][j];
                            vp[i][j] += v[i][k] * rot[k][j];
                        }
                    }
                }
                for (int i = 0; i < 3; ++i) {
                    for (int j = 0; j < 3; ++j) {
                        double x = 0.0;
                        for (int k = 0; k < 3; ++k) {
                            x += rot[k][i] * ap[k][j];
                        }
                        a[i][j] = x;
                    }
                }
                v = vp;
            }
        }
    }
    std::array<int, 3> order{0, 1, 2};
    std::sort(order.begin(), order.end(), [&](int x, int y) { return a[x][x] > a[y][y]; });
    for (int k = 0; k < 3; ++k) {
        const int src = order[static_cast<std::size_t>(k)];
        values[k] = a[src][src];
        for (int r = 0; r < 3; ++r) {
            vectors[k][r] = v[r][src];
        }
    }
}

Expected<RigidFit> fitRigid(std::span<const glm::dvec3> trackerM,
                            std::span<const glm::dvec3> boothM,
                            const RigidFitOptions& options)
{
    const std::size_t n = trackerM.size();
    if (n != boothM.size()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{} tracker readings for {} booth points", n, boothM.size()));
    }
    if (n < 3) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{} points: the tracker's pose needs at least 3 (better 6 or "
                                     "more), not all on one line",
                                     n));
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (!finite(trackerM[i]) || !finite(boothM[i])) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("point {}: not a finite number", i + 1));
        }
    }
    RigidFit fit;
    fit.spreadM = lineSpread(boothM);
    const double trackerSpread = lineSpread(trackerM);
    if (fit.spreadM < options.minSpreadM || trackerSpread < options.minSpreadM) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("the points lie (nearly) on one line (RMS {:.1f} mm from it in "
                            "the booth, {:.1f} mm as the tracker saw them; at least {:.0f} "
                            "mm needed): hold the marker at points spread in two or three "
                            "directions",
                            fit.spreadM * 1e3, trackerSpread * 1e3, options.minSpreadM * 1e3));
    }
    const glm::dvec3 pc = mean(trackerM);
    const glm::dvec3 qc = mean(boothM);
    glm::dmat3 h(0.0); // sum of (p - pc)(q - qc)^T
    for (std::size_t i = 0; i < n; ++i) {
        h += glm::outerProduct(trackerM[i] - pc, boothM[i] - qc);
    }
    // H = U S V^T from the eigenvectors V of H^T H; u_i = H v_i / s_i.
    glm::dvec3 s2;
    glm::dmat3 v;
    symmetricEigen(glm::transpose(h) * h, s2, v);
    if (glm::determinant(v) < 0.0) {
        v[2] = -v[2];
    }
    const double s0 = std::sqrt(std::max(s2[0], 0.0));
    const double s1 = std::sqrt(std::max(s2[1], 0.0));
    if (!(s1 > 1e-9 * s0) || s0 <= 0.0) {
        return makeError(ErrorCode::InvalidArgument,
                         "the points are degenerate (no two independent directions)");
    }
    glm::dvec3 u0 = h * v[0] / s0;
    glm::dvec3 u1 = h * v[1] / s1;
    u0 = glm::normalize(u0);
    u1 = glm::normalize(u1 - glm::dot(u1, u0) * u0);
    const glm::dmat3 u(u0, u1, glm::cross(u0, u1));
    // With U and V both rotations the third singular value carries the sign, and R = V U^T is the
    // optimal rotation (Kabsch with d = sign(det(V U^T)) folded in).
    fit.T_booth_tracker.rotation = v * glm::transpose(u);
    fit.T_booth_tracker.translation = qc - fit.T_booth_tracker.rotation * pc;

    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const double r = glm::length(fit.T_booth_tracker.apply(trackerM[i]) - boothM[i]);
        fit.residualsM.push_back(r);
        sum += r * r;
        if (r > fit.residualsM[fit.worst]) {
            fit.worst = i;
        }
    }
    fit.rmsM = std::sqrt(sum / static_cast<double>(n));
    if (!(fit.rmsM <= options.maxRmsM)) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("the fit's RMS residual is {:.1f} mm (at most {:.1f} mm "
                            "accepted); point {} is off by {:.1f} mm: check that its booth "
                            "position and tracker reading belong together (order, units, "
                            "a typo) and measure again",
                            fit.rmsM * 1e3, options.maxRmsM * 1e3, fit.worst + 1,
                            fit.residualsM[fit.worst] * 1e3));
    }
    return fit;
}

Expected<StandFit> fitStand(std::span<const StandReading> readings,
                            double panelWidthM,
                            double panelHeightM,
                            const StandFitOptions& options)
{
    if (readings.size() < 2) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{} reading(s): the stand needs two or three, at different "
                                     "tilts",
                                     readings.size()));
    }
    if (!(panelWidthM > 0.0 && panelHeightM > 0.0 && panelWidthM < 5.0 && panelHeightM < 5.0)) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("panel size {} x {} m is not plausible", panelWidthM, panelHeightM));
    }
    StandFit fit;
    glm::dmat3 scatter(0.0);
    for (std::size_t i = 0; i < readings.size(); ++i) {
        const auto& r = readings[i];
        const auto tilt = tiltFromGravity(r.gravityPanel);
        if (!tilt || !std::isfinite(r.topHeightM) || !std::isfinite(r.topDepthM)) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("reading {}: gravity ({:.3f}, {:.3f}, {:.3f}) m/s^2 gives "
                                         "no tilt (not 1 g, or along the hinge), or a tape value "
                                         "is missing",
                                         i + 1, r.gravityPanel.x, r.gravityPanel.y,
                                         r.gravityPanel.z));
        }
        fit.tiltsRad.push_back(*tilt);
        const glm::dvec3 g = glm::normalize(r.gravityPanel);
        scatter += glm::outerProduct(g, g);
    }
    const auto [lo, hi] = std::minmax_element(fit.tiltsRad.begin(), fit.tiltsRad.end());
    if (*hi - *lo < options.minTiltSpreadRad) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("the tilts span only {:.1f} degrees; tilt the panel at least "
                                     "{:.0f} degrees between readings",
                                     (*hi - *lo) * 180.0 / 3.14159265358979323846,
                                     options.minTiltSpreadRad * 180.0 / 3.14159265358979323846));
    }
    // Gravity turns in the plane perpendicular to the hinge: the hinge is the direction the
    // gravity readings leave out (the smallest eigenvector of their scatter).
    glm::dvec3 values;
    glm::dmat3 vectors;
    symmetricEigen(scatter, values, vectors);
    fit.hingeAxisPanel = vectors[2] * (vectors[2].x < 0.0 ? -1.0 : 1.0);
    fit.axisAngleRad = std::acos(std::clamp(fit.hingeAxisPanel.x, -1.0, 1.0));

    // Top edge of the panel at tilt t: y = H + L cos t, z = Z - L sin t (stand.h's panelPose), with
    // L = hinge-to-panel + panel height. Linear least squares in (H, Z, L).
    glm::dmat3 ata(0.0);
    glm::dvec3 atb(0.0);
    for (std::size_t i = 0; i < readings.size(); ++i) {
        const double c = std::cos(fit.tiltsRad[i]);
        const double s = std::sin(fit.tiltsRad[i]);
        const glm::dvec3 rowY{1.0, 0.0, c};
        const glm::dvec3 rowZ{0.0, 1.0, -s};
        ata += glm::outerProduct(rowY, rowY) + glm::outerProduct(rowZ, rowZ);
        atb += rowY * readings[i].topHeightM + rowZ * readings[i].topDepthM;
    }
    if (std::abs(glm::determinant(ata)) < 1e-9) {
        return makeError(ErrorCode::InvalidArgument, "the readings do not determine the hinge");
    }
    const glm::dvec3 x = glm::inverse(ata) * atb;
    double sum = 0.0;
    for (std::size_t i = 0; i < readings.size(); ++i) {
        const double ey = x[0] + x[2] * std::cos(fit.tiltsRad[i]) - readings[i].topHeightM;
        const double ez = x[1] - x[2] * std::sin(fit.tiltsRad[i]) - readings[i].topDepthM;
        sum += ey * ey + ez * ez;
    }
    fit.rmsM = std::sqrt(sum / static_cast<double>(readings.size()));
    if (!(fit.rmsM <= options.maxRmsM)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("the tape positions disagree with the tilts by {:.1f} mm RMS "
                                     "(at most {:.1f} mm accepted): measure the top edge's middle "
                                     "again at each tilt",
                                     fit.rmsM * 1e3, options.maxRmsM * 1e3));
    }
    const double hingeToPanel = x[2] - panelHeightM;
    if (hingeToPanel < -options.maxRmsM) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("the top edge is {:.3f} m from the hinge, less than the "
                                     "panel's height {:.3f} m: check the panel height and the tape "
                                     "readings",
                                     x[2], panelHeightM));
    }
    fit.stand.hingeM = glm::dvec3{0.0, x[0], x[1]};
    fit.stand.hingeToPanelM = std::max(hingeToPanel, 0.0);
    fit.stand.panelWidthM = panelWidthM;
    fit.stand.panelHeightM = panelHeightM;
    return fit;
}

} // namespace replica::pipeline::scene
