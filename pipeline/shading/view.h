// The viewing set-up in the booth frame: panel pose from the stand's tilt, eye position, and the
// per-pixel shading point (position, geometric and normal-mapped normals) on the virtual surface.
#pragma once

#include <glm/vec3.hpp>

#include <pipeline/brdf/ward.h>
#include <pipeline/surface/scene.h>

namespace replica::pipeline::shading {

using Vec3 = glm::dvec3;

// A rectangle in the booth frame with unit axes; normal = cross(right, up) faces the viewer.
struct PanelPose {
    Vec3 centre{0.0};
    Vec3 right{1.0, 0.0, 0.0};
    Vec3 up{0.0, 1.0, 0.0};
    Vec3 normal{0.0, 0.0, 1.0};
};

// Stand hinge: the panel rotates about a horizontal axis (+x) through 'hinge'; at tilt 0 it stands
// vertical facing +z, positive tilt leans its top back (away from the viewer, towards the ceiling
// light's side). The panel's bottom edge sits 'bottomOffsetM' above the hinge along the panel.
// (Stand-in until the scene state's hinge model is merged; same conventions.)
struct StandModel {
    Vec3 hinge{0.0, 0.08, 0.10};
    double bottomOffsetM = 0.02;
};

PanelPose panelPoseFromTilt(const StandModel& stand, double tiltDeg, double surfaceHeightM);

struct View {
    PanelPose panel;
    Vec3 eye{0.0, 0.45, 0.75};
    int pixelsX = 96;
    int pixelsY = 60;
};

// What one pixel sees: the point on the surface and its frame.
struct ShadingPoint {
    Vec3 p{0.0};
    Vec3 nGeo{0.0, 0.0, 1.0};
    Vec3 nShade{0.0, 0.0, 1.0};
    Vec3 right{1.0, 0.0, 0.0}; // macro tangent frame (for horizon azimuths)
    Vec3 up{0.0, 1.0, 0.0};
    double texX = 0.0; // fractional texel coordinates in the scene
    double texY = 0.0;
    int tx = 0;
    int ty = 0;
};

// The pixel grid covers the whole surface. normals: the scene's normal map (bilinear,
// renormalised); empty means flat.
ShadingPoint shadingPoint(const View& view,
                          const surface::SurfaceScene& scene,
                          const std::vector<Vec3>& normals,
                          int px,
                          int py);

// Bilinear interpolation of a normal map at fractional texel coordinates, renormalised (never zero:
// every stored normal has z > 0).
Vec3 sampleNormal(const std::vector<Vec3>& normals, int w, int h, double x, double y);

} // namespace replica::pipeline::shading
