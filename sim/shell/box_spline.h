// Quartic box spline of a regular patch (Stam 1998, appendix A). The 12 functions are
// homogeneous quartics in barycentric (u, v, w), each term coef/12 u^i v^j w^k.
// Control point layout (Stam's numbering, 1-based in the comments, 0-based in code):
//
//         1   2
//       3   4   5
//     6   7   8   9
//      10  11  12
//
// The patch is the triangle (8, 4, 7): vertex 8 is at w = 1, 4 at u = 1, 7 at v = 1.
// With our face (v0, v1, v2) = (8, 4, 7) (counter-clockwise), u = xi1, v = xi2.
#pragma once

namespace shellmpm {

/// Values and xi-derivatives of the 12 box-spline functions at (xi1, xi2).
/// out[q][k]: q = 0 value, 1 d/dxi1, 2 d/dxi2, 3 d2/dxi1^2, 4 d2/dxi1dxi2, 5 d2/dxi2^2.
void box_spline(double xi1, double xi2, double out[6][12]);

}  // namespace shellmpm
