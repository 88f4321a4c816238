#pragma once
// Affine transforms of scene files (JSON "transform", Mitsuba "to_world", glTF node
// matrices): a 3x4 matrix in double, so that a chain of rotations, scales and
// translations rounds once, when a point is transformed to float. Host only (the
// tracers see transformed triangles).
#include <cmath>

#include "pathbench/common/math.h"

namespace pb {

struct Affine {
  // Row-major 3x4: p' = m[r][0..2] . p + m[r][3].
  double m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

  static Affine translate(double x, double y, double z) {
    Affine a;
    a.m[0][3] = x, a.m[1][3] = y, a.m[2][3] = z;
    return a;
  }
  static Affine scale(double x, double y, double z) {
    Affine a;
    a.m[0][0] = x, a.m[1][1] = y, a.m[2][2] = z;
    return a;
  }
  // Right-handed rotation by `degrees` about `axis` (need not be unit length; not zero).
  static Affine rotate(double ax, double ay, double az, double degrees) {
    const double len = std::sqrt(ax * ax + ay * ay + az * az);
    ax /= len, ay /= len, az /= len;
    const double r = degrees * 3.14159265358979323846 / 180.0, c = std::cos(r), s = std::sin(r), t = 1 - c;
    Affine a;
    a.m[0][0] = t * ax * ax + c, a.m[0][1] = t * ax * ay - s * az, a.m[0][2] = t * ax * az + s * ay;
    a.m[1][0] = t * ax * ay + s * az, a.m[1][1] = t * ay * ay + c, a.m[1][2] = t * ay * az - s * ax;
    a.m[2][0] = t * ax * az - s * ay, a.m[2][1] = t * ay * az + s * ax, a.m[2][2] = t * az * az + c;
    return a;
  }
  // Rotation by the unit quaternion (x, y, z, w) (glTF's order).
  static Affine quaternion(double x, double y, double z, double w) {
    Affine a;
    a.m[0][0] = 1 - 2 * (y * y + z * z), a.m[0][1] = 2 * (x * y - z * w), a.m[0][2] = 2 * (x * z + y * w);
    a.m[1][0] = 2 * (x * y + z * w), a.m[1][1] = 1 - 2 * (x * x + z * z), a.m[1][2] = 2 * (y * z - x * w);
    a.m[2][0] = 2 * (x * z - y * w), a.m[2][1] = 2 * (y * z + x * w), a.m[2][2] = 1 - 2 * (x * x + y * y);
    return a;
  }

  // this * b: b applied first.
  Affine operator*(const Affine& b) const {
    Affine r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j) {
        double v = j == 3 ? m[i][3] : 0;
        for (int k = 0; k < 3; ++k) v += m[i][k] * b.m[k][j];
        r.m[i][j] = v;
      }
    return r;
  }
  Vec3f point(Vec3f p) const {
    double o[3];
    for (int i = 0; i < 3; ++i) o[i] = m[i][0] * p.x + m[i][1] * p.y + m[i][2] * p.z + m[i][3];
    return {float(o[0]), float(o[1]), float(o[2])};
  }
  Vec3f vector(Vec3f v) const {
    double o[3];
    for (int i = 0; i < 3; ++i) o[i] = m[i][0] * v.x + m[i][1] * v.y + m[i][2] * v.z;
    return {float(o[0]), float(o[1]), float(o[2])};
  }
  double determinant() const {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  }
  bool finite() const {
    for (const auto& row : m)
      for (double v : row)
        if (!std::isfinite(v)) return false;
    return true;
  }
  bool operator==(const Affine& b) const {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j)
        if (m[i][j] != b.m[i][j]) return false;
    return true;
  }
};

}  // namespace pb
