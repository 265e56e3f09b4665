// Spatial vector algebra in Featherstone's notation (RBDA = R. Featherstone, "Rigid Body
// Dynamics Algorithms", Springer 2008, chapter 2).
//
// Conventions:
//  - a motion vector is (ω; v): angular part first, then the linear velocity of the point at
//    the frame origin (RBDA 2.2); a force vector is (n; f): moment about the origin, then force.
//  - Transform B_X_A maps motion vectors from A coordinates to B coordinates. It is stored as
//    the rotation E (A coordinates -> B coordinates) and r, the position of B's origin relative
//    to A's origin, expressed in A coordinates (RBDA 2.24: X = [E 0; -E r× E]).
//  - RigidInertia holds the mass m, the first moment h = m c and the rotational inertia Ī about
//    the frame origin (RBDA 2.62: I = [Ī h×; h×ᵀ m1]).
// All types are templated on the scalar so that AD scalars run through the same code.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <type_traits>

namespace saltus::dynamics {

// The small spatial operations are forced inline: GCC otherwise leaves some of them as calls
// inside the recursions, which costs more than the arithmetic. SALTUS_LAMBDA_INLINE likewise
// on the per-joint lambdas of the kernels (joint.hpp, withJoint). Not on every one: GCC 12 stops
// with an internal error (gimple_duplicate_bb) on RNEA in nested AD scalars when both of its
// lambdas are forced.
// The sanitizer build (SALTUS_NO_FORCED_INLINE, set by SALTUS_SANITIZE) leaves inlining to the
// compiler: forced into every joint kind's case of the kernels' switches, the instrumented code of
// the AD translation units took GCC over 7 minutes each at -O1; the arithmetic is the same.
#ifdef SALTUS_NO_FORCED_INLINE
#define SALTUS_INLINE inline
#define SALTUS_LAMBDA_INLINE
#else
#define SALTUS_INLINE inline __attribute__((always_inline))
#define SALTUS_LAMBDA_INLINE __attribute__((always_inline))
#endif

template <class S> using Vec3 = Eigen::Matrix<S, 3, 1>;
template <class S> using Mat3 = Eigen::Matrix<S, 3, 3>;
template <class S> using Vec6 = Eigen::Matrix<S, 6, 1>;
template <class S> using Mat6 = Eigen::Matrix<S, 6, 6>;
template <class S> using VecX = Eigen::Matrix<S, Eigen::Dynamic, 1>;
template <class S> using MatX = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
template <class S> using Mat3X = Eigen::Matrix<S, 3, Eigen::Dynamic>;
template <class S> using Mat6X = Eigen::Matrix<S, 6, Eigen::Dynamic>;

// Argument types of the algorithms. The scalar is deduced from the Model alone (these are
// non-deduced contexts), so any vector expression of matching scalar can be passed.
template <class S> using VecRef = std::type_identity_t<Eigen::Ref<const VecX<S>>>;
template <class M> using MatOut = std::type_identity_t<Eigen::Ref<M>>;

// x× as a matrix: skew(x) * y = x × y.
template <class S>
Mat3<S> skew(const Vec3<S>& x) {
  Mat3<S> m;
  m << S(0), -x.z(), x.y(), x.z(), S(0), -x.x(), -x.y(), x.x(), S(0);
  return m;
}

// The 3-vector and 3×3 operations of the recursions, written out component by component:
// Eigen's fixed-size 3-vector expressions compile to a mix of 2-wide and scalar code whose
// partial stores and wide reloads stall store forwarding, and GCC leaves some of them as calls.
// Written out, they stay scalar-generic (AD scalars run through them unchanged).
template <class S>
SALTUS_INLINE Vec3<S> cross3(const Vec3<S>& a, const Vec3<S>& b) {  // a × b
  return Vec3<S>(S(a[1] * b[2] - a[2] * b[1]), S(a[2] * b[0] - a[0] * b[2]), S(a[0] * b[1] - a[1] * b[0]));
}
template <class S>
SALTUS_INLINE Vec3<S> mul3(const Mat3<S>& E, const Vec3<S>& x) {  // E x
  return Vec3<S>(S(E(0, 0) * x[0] + E(0, 1) * x[1] + E(0, 2) * x[2]),
                 S(E(1, 0) * x[0] + E(1, 1) * x[1] + E(1, 2) * x[2]),
                 S(E(2, 0) * x[0] + E(2, 1) * x[1] + E(2, 2) * x[2]));
}
template <class S>
SALTUS_INLINE Vec3<S> mulT3(const Mat3<S>& E, const Vec3<S>& x) {  // Eᵀ x
  return Vec3<S>(S(E(0, 0) * x[0] + E(1, 0) * x[1] + E(2, 0) * x[2]),
                 S(E(0, 1) * x[0] + E(1, 1) * x[1] + E(2, 1) * x[2]),
                 S(E(0, 2) * x[0] + E(1, 2) * x[1] + E(2, 2) * x[2]));
}
template <class S>
SALTUS_INLINE Vec3<S> add3(const Vec3<S>& a, const Vec3<S>& b) {
  return Vec3<S>(S(a[0] + b[0]), S(a[1] + b[1]), S(a[2] + b[2]));
}
template <class S>
SALTUS_INLINE Vec3<S> sub3(const Vec3<S>& a, const Vec3<S>& b) {
  return Vec3<S>(S(a[0] - b[0]), S(a[1] - b[1]), S(a[2] - b[2]));
}
template <class S>
SALTUS_INLINE Vec3<S> scale3(const Vec3<S>& a, const S& s) {
  return Vec3<S>(S(a[0] * s), S(a[1] * s), S(a[2] * s));
}
template <class S>
SALTUS_INLINE void copy3(Vec3<S>& a, const Vec3<S>& b) {
  a[0] = b[0];
  a[1] = b[1];
  a[2] = b[2];
}
template <class S>
SALTUS_INLINE void addTo3(Vec3<S>& a, const Vec3<S>& b) {
  a[0] += b[0];
  a[1] += b[1];
  a[2] += b[2];
}
template <class S>
SALTUS_INLINE void subFrom3(Vec3<S>& a, const Vec3<S>& b) {
  a[0] -= b[0];
  a[1] -= b[1];
  a[2] -= b[2];
}
template <class S>
SALTUS_INLINE S dot3(const Vec3<S>& a, const Vec3<S>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
// I x for a symmetric I: reads the lower triangle only.
template <class S>
SALTUS_INLINE Vec3<S> mulSym3(const Mat3<S>& I, const Vec3<S>& x) {
  return Vec3<S>(S(I(0, 0) * x[0] + I(1, 0) * x[1] + I(2, 0) * x[2]),
                 S(I(1, 0) * x[0] + I(1, 1) * x[1] + I(2, 1) * x[2]),
                 S(I(2, 0) * x[0] + I(2, 1) * x[1] + I(2, 2) * x[2]));
}

template <class S> struct Force;

// Spatial motion vector (ω; v) (RBDA 2.2).
template <class S>
struct Motion {
  Vec3<S> w;  // angular velocity
  Vec3<S> v;  // linear velocity of the point at the frame origin

  Motion() = default;
  SALTUS_INLINE Motion(const Vec3<S>& w_, const Vec3<S>& v_) { copy3(w, w_), copy3(v, v_); }
  // Copies component by component: Eigen copies a 3-vector as a 2-wide and a scalar move, which
  // stalls store forwarding on values just stored one by one.
  SALTUS_INLINE Motion(const Motion& o) { copy3(w, o.w), copy3(v, o.v); }
  SALTUS_INLINE Motion& operator=(const Motion& o) {
    copy3(w, o.w);
    copy3(v, o.v);
    return *this;
  }

  static Motion Zero() { return {Vec3<S>::Zero(), Vec3<S>::Zero()}; }
  SALTUS_INLINE Motion operator+(const Motion& o) const { return {add3(w, o.w), add3(v, o.v)}; }
  SALTUS_INLINE Motion operator-(const Motion& o) const { return {sub3(w, o.w), sub3(v, o.v)}; }
  SALTUS_INLINE Motion& operator+=(const Motion& o) { addTo3(w, o.w); addTo3(v, o.v); return *this; }
  SALTUS_INLINE Motion operator*(const S& s) const { return {scale3(w, s), scale3(v, s)}; }
  // crm(this) * m  (RBDA 2.31): the derivative of m moving with velocity *this.
  SALTUS_INLINE Motion cross(const Motion& m) const { return {cross3(w, m.w), add3(cross3(w, m.v), cross3(v, m.w))}; }
  // crf(this) * f  (RBDA 2.32).
  SALTUS_INLINE Force<S> crossForce(const Force<S>& f) const;
  Vec6<S> vector() const { Vec6<S> x; x << w, v; return x; }
  static Motion FromVector(const Vec6<S>& x) { return {x.template head<3>(), x.template tail<3>()}; }
};

// Spatial force vector (n; f) (RBDA 2.2).
template <class S>
struct Force {
  Vec3<S> n;  // moment about the frame origin
  Vec3<S> f;  // force

  Force() = default;
  SALTUS_INLINE Force(const Vec3<S>& n_, const Vec3<S>& f_) { copy3(n, n_), copy3(f, f_); }
  SALTUS_INLINE Force(const Force& o) { copy3(n, o.n), copy3(f, o.f); }  // see Motion
  SALTUS_INLINE Force& operator=(const Force& o) {
    copy3(n, o.n);
    copy3(f, o.f);
    return *this;
  }

  static Force Zero() { return {Vec3<S>::Zero(), Vec3<S>::Zero()}; }
  SALTUS_INLINE Force operator+(const Force& o) const { return {add3(n, o.n), add3(f, o.f)}; }
  SALTUS_INLINE Force operator-(const Force& o) const { return {sub3(n, o.n), sub3(f, o.f)}; }
  SALTUS_INLINE Force& operator+=(const Force& o) { addTo3(n, o.n); addTo3(f, o.f); return *this; }
  SALTUS_INLINE Force& operator-=(const Force& o) { subFrom3(n, o.n); subFrom3(f, o.f); return *this; }
  SALTUS_INLINE Force operator*(const S& s) const { return {scale3(n, s), scale3(f, s)}; }
  Vec6<S> vector() const { Vec6<S> x; x << n, f; return x; }
  static Force FromVector(const Vec6<S>& x) { return {x.template head<3>(), x.template tail<3>()}; }
};

template <class S>
SALTUS_INLINE Force<S> Motion<S>::crossForce(const Force<S>& f) const {
  return {add3(cross3(w, f.n), cross3(v, f.f)), cross3(w, f.f)};
}

// Scalar product of a motion and a force (power).
template <class S>
SALTUS_INLINE S dot(const Motion<S>& m, const Force<S>& f) {
  return dot3(m.w, f.n) + dot3(m.v, f.f);
}

// Plücker transform B_X_A (RBDA 2.24).
template <class S>
struct Transform {
  Mat3<S> E;  // rotation: A coordinates -> B coordinates
  Vec3<S> r;  // B origin relative to A origin, in A coordinates

  static Transform Identity() { return {Mat3<S>::Identity(), Vec3<S>::Zero()}; }

  // X m: motion from A to B coordinates.
  SALTUS_INLINE Motion<S> apply(const Motion<S>& m) const {
    return {mul3(E, m.w), mul3(E, sub3(m.v, cross3(r, m.w)))};
  }
  // X* f: force from A to B coordinates.
  SALTUS_INLINE Force<S> apply(const Force<S>& f) const {
    return {mul3(E, sub3(f.n, cross3(r, f.f))), mul3(E, f.f)};
  }
  // X⁻¹ m: motion from B to A coordinates.
  SALTUS_INLINE Motion<S> applyInverse(const Motion<S>& m) const {
    const Vec3<S> w = mulT3(E, m.w);
    return {w, add3(mulT3(E, m.v), cross3(r, w))};
  }
  // Xᵀ f = (X*)⁻¹ f: force from B to A coordinates (RBDA 2.25).
  SALTUS_INLINE Force<S> applyTranspose(const Force<S>& f) const {
    const Vec3<S> ff = mulT3(E, f.f);
    return {add3(mulT3(E, f.n), cross3(r, ff)), ff};
  }
  // (C_X_B) * (B_X_A) = C_X_A  (RBDA Table 2.2).
  SALTUS_INLINE Transform operator*(const Transform& bXa) const {
    return {E * bXa.E, bXa.r + bXa.E.transpose() * r};
  }
  // A_X_B.
  Transform inverse() const { return {E.transpose(), -(E * r)}; }

  Mat6<S> matrix() const {
    Mat6<S> X;
    X.template topLeftCorner<3, 3>() = E;
    X.template topRightCorner<3, 3>().setZero();
    X.template bottomLeftCorner<3, 3>() = -E * skew(r);
    X.template bottomRightCorner<3, 3>() = E;
    return X;
  }
  template <class T>
  Transform<T> cast() const { return {E.template cast<T>(), r.template cast<T>()}; }
};

// Rigid-body spatial inertia about the frame origin (RBDA 2.62).
template <class S>
struct RigidInertia {
  S m;         // mass
  Vec3<S> h;   // first moment of mass m c (c: centre of mass)
  Mat3<S> I;   // rotational inertia about the frame origin

  static RigidInertia Zero() { return {S(0), Vec3<S>::Zero(), Mat3<S>::Zero()}; }
  // From mass, centre of mass c and the rotational inertia about the centre of mass
  // (parallel-axis theorem, RBDA 2.63).
  static RigidInertia FromCom(const S& mass, const Vec3<S>& c, const Mat3<S>& Ic) {
    const Mat3<S> cx = skew(c);
    return {mass, c * mass, Ic - mass * cx * cx};
  }

  SALTUS_INLINE RigidInertia operator+(const RigidInertia& o) const { RigidInertia x = *this; return x += o; }
  SALTUS_INLINE RigidInertia& operator+=(const RigidInertia& o) {
    m += o.m;
    addTo3(h, o.h);
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) I(k, c) += o.I(k, c);
    return *this;
  }

  // I v  (RBDA 2.62).
  SALTUS_INLINE Force<S> operator*(const Motion<S>& v) const {
    return {add3(mulSym3(I, v.w), cross3(h, v.v)), sub3(scale3(v.v, m), cross3(h, v.w))};
  }

  // Xᵀ I X: this inertia is expressed in B coordinates; returns it in A coordinates, where
  // X = B_X_A (RBDA Table 2.5). With h' = Eᵀh, Ī' = Eᵀ Ī E and a×b× = b aᵀ − (a·b)1:
  //   h_A = h' + m r,   Ī_A = Ī' − h' rᵀ − r h_Aᵀ + (2 r·h' + m r·r) 1.
  RigidInertia transformedBy(const Transform<S>& X) const {
    const Mat3<S>& E = X.E;
    const Vec3<S>& r = X.r;
    RigidInertia out;
    out.m = m;
    const Vec3<S> h1 = mulT3(E, h);
    out.h = add3(h1, scale3(r, m));
    const S diag = S(2) * dot3(r, h1) + m * dot3(r, r);
    // Ī' = Eᵀ Ī E, one triangle, mirrored.
    Mat3<S> IE;
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) IE(k, c) = I(k, 0) * E(0, c) + I(k, 1) * E(1, c) + I(k, 2) * E(2, c);
    for (int c = 0; c < 3; ++c)
      for (int k = c; k < 3; ++k) {
        S x = E(0, k) * IE(0, c) + E(1, k) * IE(1, c) + E(2, k) * IE(2, c) - h1[k] * r[c] - r[k] * out.h[c];
        if (k == c) x += diag;
        out.I(k, c) = x;
        out.I(c, k) = x;
      }
    return out;
  }

  Mat6<S> matrix() const {
    Mat6<S> M;
    const Mat3<S> hx = skew(h);
    M.template topLeftCorner<3, 3>() = I;
    M.template topRightCorner<3, 3>() = hx;
    M.template bottomLeftCorner<3, 3>() = -hx;
    M.template bottomRightCorner<3, 3>() = Mat3<S>::Identity() * m;
    return M;
  }
  template <class T>
  RigidInertia<T> cast() const { return {T(m), h.template cast<T>(), I.template cast<T>()}; }
};

// sin q and cos q; for double in one libm call (GCC merges separate sin and cos calls only
// when it sees both in one block).
template <class S>
SALTUS_INLINE void sinCos(const S& q, S& s, S& c) {
  using std::cos;
  using std::sin;
  s = sin(q);
  c = cos(q);
}
SALTUS_INLINE void sinCos(double q, double& s, double& c) { ::sincos(q, &s, &c); }

// sin q_k and cos q_k of n angles. For double with AVX-512 or AVX2 (-march=native) in the vector
// variants of sin and cos in glibc's libmvec (x86_64 vector function ABI; libm.so pulls libmvec in
// as needed), 8 or 4 angles a call, a fifth of the time of sincos per angle, within 3 ulp of it.
#if defined(__AVX512F__) || defined(__AVX2__)
}  // namespace saltus::dynamics
#include <immintrin.h>
extern "C" {
#ifdef __AVX512F__
__m512d _ZGVeN8v_sin(__m512d);
__m512d _ZGVeN8v_cos(__m512d);
#else
__m256d _ZGVdN4v_sin(__m256d);
__m256d _ZGVdN4v_cos(__m256d);
#endif
}
namespace saltus::dynamics {
#endif
inline void sinCosMany(const double* q, int n, double* s, double* c) {
#if defined(__AVX512F__) || defined(__AVX2__)
#ifdef __AVX512F__
  constexpr int w = 8;
  const auto kernel = [](const double* x, double* sx, double* cx) {
    const __m512d v = _mm512_loadu_pd(x);
    _mm512_storeu_pd(sx, _ZGVeN8v_sin(v));
    _mm512_storeu_pd(cx, _ZGVeN8v_cos(v));
  };
#else
  constexpr int w = 4;
  const auto kernel = [](const double* x, double* sx, double* cx) {
    const __m256d v = _mm256_loadu_pd(x);
    _mm256_storeu_pd(sx, _ZGVdN4v_sin(v));
    _mm256_storeu_pd(cx, _ZGVdN4v_cos(v));
  };
#endif
  int k = 0;
  for (; k + w <= n; k += w) kernel(q + k, s + k, c + k);
  if (k < n) {  // the rest, padded with zeros
    double x[w] = {}, sx[w], cx[w];
    for (int j = k; j < n; ++j) x[j - k] = q[j];
    kernel(x, sx, cx);
    for (int j = k; j < n; ++j) s[j] = sx[j - k], c[j] = cx[j - k];
  }
#else
  for (int k = 0; k < n; ++k) sinCos(q[k], s[k], c[k]);
#endif
}

// Rotation matrix (active) by angle q about a unit axis (Rodrigues).
template <class S>
Mat3<S> axisAngle(const Vec3<S>& axis, const S& q) {
  using std::cos;
  using std::sin;
  const S c = cos(q), s = sin(q), t = S(1) - c;
  const S &x = axis.x(), &y = axis.y(), &z = axis.z();
  Mat3<S> R;
  R << t * (x * x) + c, t * (x * y) - s * z, t * (x * z) + s * y,
       t * (x * y) + s * z, t * (y * y) + c, t * (y * z) - s * x,
       t * (x * z) - s * y, t * (y * z) + s * x, t * (z * z) + c;
  return R;
}

}  // namespace saltus::dynamics
