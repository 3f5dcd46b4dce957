// Procedural shell control meshes: a rectangular sheet, a cylinder patch or tube, and
// an icosphere. All are consistently oriented (normals point +Y for the sheet and
// outward for the cylinder and sphere) and carry UVs.
#pragma once
#include "sim/scene/shell_mesh.h"

namespace shellmpm {

/// Sheet in the XZ plane centred at the origin: size (along X, along Z), quads nx x nz,
/// each split along the same diagonal so interior vertices have valence 6.
/// Vertex (i, j) (i along X, j along Z) has index j * (nx + 1) + i.
ShellMesh make_sheet(double size_x, double size_z, int nx, int nz);

/// Cylinder around the Y axis, centred at the origin: `angle_deg` of arc (360 = closed
/// tube, no seam vertices), n_around segments around and n_along along the axis.
ShellMesh make_cylinder(double radius, double height, double angle_deg, int n_around, int n_along);

/// Icosahedron subdivided `subdivisions` times and projected to the sphere:
/// 10 * 4^s + 2 vertices, every vertex valence 6 except 12 of valence 5.
ShellMesh make_sphere(double radius, int subdivisions);

}  // namespace shellmpm
