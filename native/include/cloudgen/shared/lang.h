/* cloudgen/shared/lang.h — the adaptation block for code shared by C++ and OSL.
 *
 * The cloud model (cloud_model.h) is one physical source compiled by a C++20
 * compiler and by oslc. It is written in the subset both accept; this file maps
 * the few places where the two languages differ:
 *
 *   CG_FN         function qualifier: `inline` in C++ (or `static inline`, see below), nothing in OSL
 *   CG_VEC3       3-vector: cg::vec3 in C++, `vector` in OSL
 *   CG_NAMESPACE_BEGIN/END  shared code lives in namespace cg in C++
 *   CG_IN_ARRAY   element type of a read-only float array parameter
 *   CG_FLOAT(x)   a float literal: `x`f in C++ (so no double arithmetic sneaks in;
 *                 the C++ build uses -Werror=double-promotion), plain `x` in OSL
 *   cg_imul/cg_shr  32-bit integer multiply and logical shift right with
 *                 wrap-around. OSL has only signed 32-bit ints, which wrap on
 *                 overflow; C++ signed overflow is undefined, so the C++ side
 *                 computes in uint32 and converts back (well defined in C++20).
 *   floor/sqrt/pow/log2/clamp/mix/smoothstep/min/max/sin
 *                 OSL builtins; the C++ side provides float-only versions with
 *                 OSL's safe semantics (sqrt of a negative → 0, pow of a
 *                 negative base with a non-integer exponent → 0, results that
 *                 would be infinite → 0).
 *
 * Rules for shared code: float literals only through CG_FLOAT or as small
 * integers (int→float promotion is exact and identical in both languages);
 * loops use `i += 1`; no bool (use int); no references except CG_OUT; never
 * assign to a function parameter (OSL forbids it): copy it to a local first.
 */
#ifndef CLOUDGEN_SHARED_LANG_H
#define CLOUDGEN_SHARED_LANG_H

#ifdef CG_OSL
/* ------------------------------------------------------------------ OSL --- */
#define CG_FN
#define CG_VEC3 vector
#define CG_FLOAT(x) x
#define CG_OUT(T) output T
#define CG_IN_ARRAY float
#define CG_NAMESPACE_BEGIN
#define CG_NAMESPACE_END

int cg_imul(int a, int b) { return a * b; }
int cg_shr(int a, int n) { return (a >> n) & ((1 << (32 - n)) - 1); }

#else
/* ------------------------------------------------------------------ C++ --- */
#include <cmath>
#include <cstdint>

/* A kernel object file compiled for one instruction set (native/src/simd/) defines
 * CG_FN as `static inline` before including: its copies then have internal
 * linkage and the linker can never mix them with the baseline ones. */
#ifndef CG_FN
#define CG_FN inline
#endif
#define CG_VEC3 ::cg::vec3
#define CG_FLOAT(x) x##f
#define CG_OUT(T) T&
#define CG_IN_ARRAY const float
#define CG_NAMESPACE_BEGIN namespace cg {
#define CG_NAMESPACE_END }

namespace cg {

struct vec3 {
  float v[3];
  constexpr vec3() : v{0, 0, 0} {}
  constexpr vec3(float x, float y, float z) : v{x, y, z} {}
  constexpr float& operator[](int i) { return v[i]; }
  constexpr float operator[](int i) const { return v[i]; }
};
constexpr vec3 operator+(vec3 a, vec3 b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
constexpr vec3 operator-(vec3 a, vec3 b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
constexpr vec3 operator*(vec3 a, float s) { return {a[0] * s, a[1] * s, a[2] * s}; }
constexpr vec3 operator*(float s, vec3 a) { return a * s; }

CG_FN int cg_imul(int a, int b) {
  return static_cast<int>(static_cast<std::uint32_t>(a) * static_cast<std::uint32_t>(b));
}
CG_FN int cg_shr(int a, int n) { return static_cast<int>(static_cast<std::uint32_t>(a) >> n); }

/* OSL-compatible float math. Unqualified calls in namespace cg find these. */
CG_FN float floor(float x) { return std::floor(x); }
CG_FN float sin(float x) { return std::sin(x); }
CG_FN float fabs(float x) { return std::fabs(x); }
CG_FN float log2(float x) { return x > 0 ? std::log2(x) : 0.0f; }
CG_FN float sqrt(float x) { return x > 0 ? std::sqrt(x) : 0.0f; }
CG_FN float min(float a, float b) { return a < b ? a : b; }
CG_FN float max(float a, float b) { return a > b ? a : b; }
CG_FN float clamp(float x, float lo, float hi) { return min(max(x, lo), hi); }
CG_FN float mix(float a, float b, float t) { return a * (1.0f - t) + b * t; }
CG_FN float smoothstep(float e0, float e1, float x) {
  if (x < e0) return 0.0f;
  if (x >= e1) return 1.0f;
  const float t = (x - e0) / (e1 - e0);
  return t * t * (3.0f - 2.0f * t);
}
CG_FN float pow(float b, float e) {
  if (b < 0.0f && std::floor(e) != e) return 0.0f;
  const float r = std::pow(b, e);
  return std::isfinite(r) ? r : 0.0f;
}

}  // namespace cg
#endif

#endif /* CLOUDGEN_SHARED_LANG_H */
