// camera.cpp — view frustum, nearest visible depth and the camera-fitted voxel.
#include "cloudgen/camera.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "json_limits.h"

namespace cg {

namespace {

using json = nlohmann::json;

float dot(vec3 a, vec3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

double read_number(const json& doc, const char* key, double lo, double hi, const std::string& where) {
  const json& v = doc.at(key);
  if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo || v.get<double>() > hi)
    throw ParamError(where + ": '" + key + "' must be a number in [" + json(lo).dump() + ", " + json(hi).dump() +
                     "]; got " + brief(v));
  return v.get<double>();
}

// Camera-space point → cloud space, and camera-space direction → cloud space.
vec3 to_cloud(const CameraView& c, double x, double y, double z, double w) {
  vec3 out;
  for (int r = 0; r < 3; ++r)
    out[r] = float(c.camera_to_cloud[r][0] * x + c.camera_to_cloud[r][1] * y + c.camera_to_cloud[r][2] * z +
                   c.camera_to_cloud[r][3] * w);
  return out;
}

using Polygon = std::vector<vec3>;

// Sutherland–Hodgman: the part of a convex polygon on the inside of a plane.
Polygon clip(const Polygon& poly, const Plane& p) {
  Polygon out;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const vec3 a = poly[i], b = poly[(i + 1) % poly.size()];
    const float da = dot(p.n, a) + p.d, db = dot(p.n, b) + p.d;
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) {
      const float t = da / (da - db);
      out.push_back(a + (b - a) * t);
    }
  }
  return out;
}

}  // namespace

CameraView parse_camera(std::string_view text, std::string_view origin) {
  const std::string where(origin);
  json doc = parse_json_limited(text, where, kSmallFileLimits);
  if (!doc.is_object()) throw ParamError(where + ": expected a JSON object (see docs/camera.md)");
  static const char* const known[] = {"camera_to_cloud", "tan_half_fov",     "resolution", "near",
                                      "margin",          "pixels_per_voxel", "type",       "light_directions"};
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    const std::string& key = it.key();  // not a structured binding: clang 14 cannot capture one
    if (std::find_if(std::begin(known), std::end(known), [&](const char* k) { return key == k; }) == std::end(known))
      throw ParamError(where + ": unknown key '" + brief_text(key) + "'");
  }
  for (const char* key : {"camera_to_cloud", "tan_half_fov", "resolution"})
    if (!doc.contains(key)) throw ParamError(where + ": missing '" + key + "'");
  if (doc.contains("type") && doc["type"] != "PERSP")
    throw ParamError(where + ": only perspective cameras are supported; got type " + brief(doc["type"]));

  CameraView c;
  const json& m = doc["camera_to_cloud"];
  const std::string bad_matrix = where + ": 'camera_to_cloud' must be a 4x4 list of rows of finite numbers";
  if (!m.is_array() || m.size() != 4) throw ParamError(bad_matrix);
  for (int r = 0; r < 4; ++r) {
    if (!m[r].is_array() || m[r].size() != 4) throw ParamError(bad_matrix);
    for (int k = 0; k < 4; ++k) {
      if (!m[r][k].is_number() || !std::isfinite(m[r][k].get<double>())) throw ParamError(bad_matrix);
      c.camera_to_cloud[r][k] = m[r][k].get<double>();
      if (std::fabs(c.camera_to_cloud[r][k]) > 1e9)
        throw ParamError(where + ": 'camera_to_cloud' values must be within ±1e9");
    }
  }
  // Rigid: the rotation part orthonormal (tolerance 1e-3), bottom row 0 0 0 1.
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      double s = 0;
      for (int r = 0; r < 3; ++r) s += c.camera_to_cloud[r][a] * c.camera_to_cloud[r][b];
      if (std::fabs(s - (a == b ? 1.0 : 0.0)) > 1e-3)
        throw ParamError(where +
                         ": 'camera_to_cloud' must be a rigid transform (rotation and translation, "
                         "no scale or shear; remove the objects' scale)");
    }
  if (c.camera_to_cloud[3][0] != 0 || c.camera_to_cloud[3][1] != 0 || c.camera_to_cloud[3][2] != 0 ||
      c.camera_to_cloud[3][3] != 1)
    throw ParamError(where + ": 'camera_to_cloud' last row must be [0, 0, 0, 1]");

  const json& fov = doc["tan_half_fov"];
  const json& res = doc["resolution"];
  if (!fov.is_array() || fov.size() != 2 || !res.is_array() || res.size() != 2)
    throw ParamError(where + ": 'tan_half_fov' and 'resolution' must be lists of two numbers");
  for (int i = 0; i < 2; ++i) {
    if (!fov[i].is_number() || !(fov[i].get<double>() >= 1e-4 && fov[i].get<double>() <= 1e4))
      throw ParamError(where + ": 'tan_half_fov' values must be in [0.0001, 10000]; got " + brief(fov));
    if (!res[i].is_number_integer() || res[i].get<long long>() < 1 || res[i].get<long long>() > 65536)
      throw ParamError(where + ": 'resolution' values must be integers in [1, 65536]; got " + brief(res));
    c.tan_half_fov[i] = fov[i].get<float>();
    c.resolution[i] = res[i].get<int>();
  }
  if (doc.contains("near")) c.near_clip = float(read_number(doc, "near", 1e-6, 1e6, where));
  if (doc.contains("margin")) c.margin = float(read_number(doc, "margin", 0.0, 1e9, where));
  if (doc.contains("pixels_per_voxel"))
    c.pixels_per_voxel = float(read_number(doc, "pixels_per_voxel", kMinPixelsPerVoxel, kMaxPixelsPerVoxel, where));
  if (doc.contains("light_directions")) {
    const json& l = doc["light_directions"];
    const std::string bad = where +
                            ": 'light_directions' must be a list of at most 4 non-zero [x, y, z] directions "
                            "towards the lights, in the cloud's frame";
    if (!l.is_array() || l.size() > c.lights.size()) throw ParamError(bad);
    for (const json& d : l) {
      if (!d.is_array() || d.size() != 3) throw ParamError(bad);
      double v[3], len = 0;
      for (int i = 0; i < 3; ++i) {
        if (!d[i].is_number() || !std::isfinite(d[i].get<double>()) || std::fabs(d[i].get<double>()) > 1e9)
          throw ParamError(bad);
        v[i] = d[i].get<double>();
        len += v[i] * v[i];
      }
      if (!(len > 1e-12)) throw ParamError(bad);
      len = std::sqrt(len);
      c.lights[c.light_count++] = {float(v[0] / len), float(v[1] / len), float(v[2] / len)};
    }
  }
  return c;
}

Frustum view_frustum(const CameraView& c, float widen) {
  // Inside normals in camera space (the camera looks along -Z).
  const float tx = c.tan_half_fov[0], ty = c.tan_half_fov[1];
  const double sides[4][3] = {{-1, 0, -tx}, {1, 0, -tx}, {0, -1, -ty}, {0, 1, -ty}};
  const vec3 eye = to_cloud(c, 0, 0, 0, 1);
  Frustum f;
  for (int i = 0; i < 4; ++i) {
    const double len = std::sqrt(sides[i][0] * sides[i][0] + sides[i][1] * sides[i][1] + sides[i][2] * sides[i][2]);
    const vec3 n = to_cloud(c, sides[i][0] / len, sides[i][1] / len, sides[i][2] / len, 0);
    f.planes[i] = {n, -dot(n, eye) + widen};
  }
  const vec3 forward = to_cloud(c, 0, 0, -1, 0);
  f.planes[4] = {forward, -dot(forward, eye) - c.near_clip + widen};
  f.light_count = c.light_count;
  f.lights = c.lights;
  return f;
}

bool box_outside(const Frustum& f, vec3 lo, vec3 hi) {
  // Plane i separates the box from the frustum when the box lies wholly
  // outside it; it separates the box from the frustum swept towards light L
  // too when moving away from L (the shadow ray backwards) never enters it:
  // n·L >= 0.
  bool outside[5];
  bool outside_view = false;
  for (int i = 0; i < 5; ++i) {
    const Plane& p = f.planes[i];
    // The box corner farthest along the normal.
    const vec3 far{p.n[0] >= 0 ? hi[0] : lo[0], p.n[1] >= 0 ? hi[1] : lo[1], p.n[2] >= 0 ? hi[2] : lo[2]};
    outside[i] = dot(p.n, far) + p.d < 0;
    outside_view = outside_view || outside[i];
  }
  if (!outside_view) return false;
  for (int l = 0; l < f.light_count; ++l) {
    bool separated = false;
    for (int i = 0; i < 5 && !separated; ++i) separated = outside[i] && dot(f.planes[i].n, f.lights[l]) >= 0.0f;
    if (!separated) return false;
  }
  return true;
}

float default_margin(const Model& m) {
  const float longest = std::max({m.box[0], m.box[1], m.box[2]});
  if (!(m.density > 0.0f)) return 0.0f;
  return std::min(16.0f / m.density, longest);
}

CameraFit fit_camera(const Model& m, const CameraView& c) {
  CameraFit fit;
  fit.margin = c.margin >= 0.0f ? c.margin : default_margin(m);
  fit.region = view_frustum(c, fit.margin);
  const Frustum view = view_frustum(c, 0.0f);
  const vec3 eye = to_cloud(c, 0, 0, 0, 1);
  const vec3 forward = to_cloud(c, 0, 0, -1, 0);
  const vec3 h = m.box * 0.5f;

  // The nearest visible point of the box is a vertex of box ∩ frustum (a
  // linear function's minimum over a convex polytope): a vertex of a box face
  // clipped by the frustum, or of the near rectangle clipped by the box.
  std::vector<Polygon> faces;
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {-1.0f, 1.0f}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      Polygon face(4);
      const float su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
      for (int k = 0; k < 4; ++k) {
        face[k][axis] = side * h[axis];
        face[k][u] = su[k] * h[u];
        face[k][v] = sv[k] * h[v];
      }
      for (const Plane& p : view.planes) face = clip(face, p);
      faces.push_back(face);
    }
  Polygon near_rect;
  const float n = c.near_clip, tx = c.tan_half_fov[0], ty = c.tan_half_fov[1];
  for (const auto& [sx, sy] : {std::pair{-1.0f, -1.0f}, {1.0f, -1.0f}, {1.0f, 1.0f}, {-1.0f, 1.0f}})
    near_rect.push_back(to_cloud(c, sx * tx * n, sy * ty * n, -n, 1));
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {-1.0f, 1.0f}) {
      Plane p{};
      p.n[axis] = -side;  // inside: side·x <= h
      p.d = h[axis];
      near_rect = clip(near_rect, p);
    }
  faces.push_back(near_rect);

  float nearest = INFINITY;
  for (const Polygon& poly : faces)
    for (const vec3& q : poly) nearest = std::min(nearest, dot(forward, q - eye));
  if (!(nearest < INFINITY)) {
    // Nothing of the box is in view: one voxel over the box, and a region no
    // point passes (a plane beyond the box, no lights), so a bake evaluates
    // nothing and writes an empty grid.
    fit.voxel = std::max({m.box[0], m.box[1], m.box[2]});
    fit.region.planes[0] = {vec3(1, 0, 0), -2.0f * fit.voxel - 1.0f};
    fit.region.light_count = 0;
    return fit;
  }
  fit.visible = true;
  fit.nearest_depth = std::max(nearest, c.near_clip);
  fit.footprint = 2.0f * fit.nearest_depth *
                  std::min(c.tan_half_fov[0] / float(c.resolution[0]), c.tan_half_fov[1] / float(c.resolution[1]));
  fit.voxel = fit.footprint * (c.pixels_per_voxel > 0.0f ? c.pixels_per_voxel : kDefaultPixelsPerVoxel);
  return fit;
}

}  // namespace cg
