#include "render/renderer.hpp"

#include <GL/osmesa.h>
#include <GL/gl.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

// LeakSanitizer (the ASan builds of the tests and of saltus): Mesa's OSMesa keeps process-wide
// state allocated on the first OSMesaMakeCurrent (glapi dispatch, the current-context record)
// that it never frees, even after OSMesaDestroyContext; those reports come from inside
// libOSMesa, not from Saltus. This hook is read only when LeakSanitizer is linked in.
extern "C" const char* __lsan_default_suppressions() { return "leak:libOSMesa.so\n"; }

namespace saltus::render {

namespace {

void loadMatrix(const Eigen::Matrix4d& M) {
  const Eigen::Matrix4d copy = M;  // column-major, as OpenGL expects
  glLoadMatrixd(copy.data());
}
void multMatrix(const Eigen::Matrix4d& M) {
  const Eigen::Matrix4d copy = M;
  glMultMatrixd(copy.data());
}

void drawMesh(const Mesh& m) {
  glVertexPointer(3, GL_FLOAT, 0, m.vertices.data());
  glNormalPointer(GL_FLOAT, 0, m.normals.data());
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(m.triangles.size()), GL_UNSIGNED_INT, m.triangles.data());
}

// A square texture of `n` × `n` texels: a 2 × 2 checker (stripes = false) or one stripe across u.
std::vector<std::uint8_t> patternTexture(int n, bool stripes, const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  std::vector<std::uint8_t> texels(static_cast<std::size_t>(n) * n * 3);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const bool first = stripes ? i < n / 4 : ((i < n / 2) != (j < n / 2));
      const Eigen::Vector3f& c = first ? a : b;
      for (int k = 0; k < 3; ++k) texels[(static_cast<std::size_t>(j) * n + i) * 3 + k] = static_cast<std::uint8_t>(255 * c[k]);
    }
  return texels;
}

GLuint makeTexture(const std::vector<std::uint8_t>& texels, int n) {
  GLuint id = 0;
  glGenTextures(1, &id);
  glBindTexture(GL_TEXTURE_2D, id);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_GENERATE_MIPMAP, GL_TRUE);  // GL 1.4: mipmaps against far-field aliasing
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, n, n, 0, GL_RGB, GL_UNSIGNED_BYTE, texels.data());
  return id;
}

// Projection onto the plane n·x = n·p along the direction L towards a light at infinity:
// S = (P·L) I − L Pᵀ with P = (n, −n·p), L = (l, 0) (planar projected shadows).
Eigen::Matrix4d shadowMatrix(const Eigen::Vector3d& n, const Eigen::Vector3d& p, const Eigen::Vector3d& l) {
  const Eigen::Vector4d P(n.x(), n.y(), n.z(), -n.dot(p));
  const Eigen::Vector4d L(l.x(), l.y(), l.z(), 0);
  return P.dot(L) * Eigen::Matrix4d::Identity() - L * P.transpose();
}

Eigen::Matrix4d shapeMatrix(const Eigen::Isometry3d& X_WG, const Eigen::Vector3d& scale) {
  Eigen::Matrix4d M = X_WG.matrix();
  M.topLeftCorner<3, 3>() = M.topLeftCorner<3, 3>() * scale.asDiagonal();
  return M;
}

}  // namespace

struct Renderer::Gl {
  OSMesaContext context = nullptr;
  std::vector<std::uint8_t> rgba;  // the colour buffer OSMesa draws into
  int width = 0, height = 0;
  GLuint checker = 0, stripes = 0;
  Mesh cylinder = cylinderMesh(16), cone = coneMesh(16), disk = diskMesh(48);
};

Renderer::Renderer(const SceneGeometry& geometry, const RenderSettings& settings)
    : geometry_(geometry), settings_(settings), gl_(std::make_unique<Gl>()) {
  if (settings.width < 2 || settings.height < 2 || settings.width > 8192 || settings.height > 8192)
    throw std::runtime_error("render: image size " + std::to_string(settings.width) + "x" +
                             std::to_string(settings.height) + " is outside 2 … 8192");
  if (settings.supersample < 1 || settings.supersample > 4)
    throw std::runtime_error("render: supersampling factor must be 1 … 4, got " + std::to_string(settings.supersample));
  gl_->width = settings.width * settings.supersample;
  gl_->height = settings.height * settings.supersample;
  const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 8,
                         OSMESA_PROFILE, OSMESA_COMPAT_PROFILE, 0};
  gl_->context = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!gl_->context) throw std::runtime_error("render: cannot create an OSMesa (off-screen OpenGL) context");
  gl_->rgba.assign(static_cast<std::size_t>(gl_->width) * gl_->height * 4, 0);
  if (!OSMesaMakeCurrent(gl_->context, gl_->rgba.data(), GL_UNSIGNED_BYTE, gl_->width, gl_->height)) {
    OSMesaDestroyContext(gl_->context);
    throw std::runtime_error("render: cannot make the OSMesa context current");
  }
  OSMesaPixelStore(OSMESA_Y_UP, 0);  // first row of the buffer = top of the image
  gl_->checker = makeTexture(patternTexture(64, false, {0.86f, 0.86f, 0.84f}, {0.70f, 0.71f, 0.70f}), 64);
  gl_->stripes = makeTexture(patternTexture(64, true, {0.85f, 0.78f, 0.35f}, {0.22f, 0.23f, 0.25f}), 64);
  rgb_.assign(static_cast<std::size_t>(settings.width) * settings.height * 3, 0);
}

Renderer::~Renderer() {
  if (gl_ && gl_->context) OSMesaDestroyContext(gl_->context);
}

void Renderer::draw(const Camera& camera, const FrameContent& frame) {
  const Eigen::Vector3d light = setUpFrame(camera);
  // Surfaces, each marking its pixels in the stencil buffer (value s + 1) for its shadows.
  if (settings_.surfaces) {
    glEnable(GL_STENCIL_TEST);
    drawSurfaces(frame);
    if (settings_.shadows) drawShadows(frame, light);
    glDisable(GL_STENCIL_TEST);
  }
  drawModel(frame);
  // Overlays, drawn over everything so that arrows inside a body stay visible: contact-force
  // arrows (shaft and head), impulse markers (ring and star in the surface's plane).
  glClear(GL_DEPTH_BUFFER_BIT);
  glDisable(GL_FOG);
  drawArrows(frame);
  if (!frame.markers.empty()) drawMarkers(frame);
  glFinish();
  downsample();
}

// Clears the buffers and sets the projection, the view, the lights and the fog; returns the
// direction towards the key light (world).
Eigen::Vector3d Renderer::setUpFrame(const Camera& camera) {
  if (!OSMesaMakeCurrent(gl_->context, gl_->rgba.data(), GL_UNSIGNED_BYTE, gl_->width, gl_->height))
    throw std::runtime_error("render: cannot make the OSMesa context current");
  const auto& bg = settings_.background;
  glViewport(0, 0, gl_->width, gl_->height);
  glClearColor(bg.x(), bg.y(), bg.z(), 1);
  glClearStencil(0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glShadeModel(GL_SMOOTH);
  glEnable(GL_NORMALIZE);
  glEnableClientState(GL_VERTEX_ARRAY);
  glEnableClientState(GL_NORMAL_ARRAY);

  glMatrixMode(GL_PROJECTION);
  loadMatrix(camera.projection(double(settings_.width) / settings_.height));
  glMatrixMode(GL_MODELVIEW);
  const Eigen::Matrix4d view = camera.view();
  loadMatrix(view);

  // Lights, given in world coordinates under the view matrix: a key light from light_direction,
  // a dim fill light from the camera, ambient.
  const Eigen::Vector3d light = settings_.light_direction.normalized();
  const Eigen::Vector3d to_camera = (camera.eye - camera.target).normalized();
  const GLfloat key_position[] = {float(light.x()), float(light.y()), float(light.z()), 0};
  const GLfloat fill_position[] = {float(to_camera.x()), float(to_camera.y()), float(to_camera.z()), 0};
  const GLfloat key_diffuse[] = {0.72f, 0.72f, 0.70f, 1}, fill_diffuse[] = {0.25f, 0.25f, 0.27f, 1};
  const GLfloat specular[] = {0.35f, 0.35f, 0.35f, 1}, none[] = {0, 0, 0, 1}, ambient[] = {0.30f, 0.30f, 0.32f, 1};
  glEnable(GL_LIGHTING);
  glLightModelfv(GL_LIGHT_MODEL_AMBIENT, ambient);
  glLightModeli(GL_LIGHT_MODEL_LOCAL_VIEWER, GL_TRUE);
  glEnable(GL_LIGHT0);
  glLightfv(GL_LIGHT0, GL_POSITION, key_position);
  glLightfv(GL_LIGHT0, GL_DIFFUSE, key_diffuse);
  glLightfv(GL_LIGHT0, GL_SPECULAR, specular);
  glLightfv(GL_LIGHT0, GL_AMBIENT, none);
  glEnable(GL_LIGHT1);
  glLightfv(GL_LIGHT1, GL_POSITION, fill_position);
  glLightfv(GL_LIGHT1, GL_DIFFUSE, fill_diffuse);
  glLightfv(GL_LIGHT1, GL_SPECULAR, none);
  glLightfv(GL_LIGHT1, GL_AMBIENT, none);
  glEnable(GL_COLOR_MATERIAL);
  glColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);

  if (settings_.fog_end > settings_.fog_start) {
    const GLfloat fog_colour[] = {bg.x(), bg.y(), bg.z(), 1};
    glEnable(GL_FOG);
    glFogi(GL_FOG_MODE, GL_LINEAR);
    glFogfv(GL_FOG_COLOR, fog_colour);
    glFogf(GL_FOG_START, float(settings_.fog_start));
    glFogf(GL_FOG_END, float(settings_.fog_end));
  } else {
    glDisable(GL_FOG);
  }
  return light;
}

// The surfaces: a checkered square, or a striped slab for a belt, its stripes shifted by the
// belt's travel; each marks its pixels in the stencil buffer with s + 1.
void Renderer::drawSurfaces(const FrameContent& frame) {
  const scene::Scene& scene = geometry_.scene();
  glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1, 1);  // behind the shadows drawn exactly on the plane
  glEnable(GL_TEXTURE_2D);
  glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
  const GLfloat surface_specular[] = {0.05f, 0.05f, 0.05f, 1};
  glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, surface_specular);
  for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
    const scene::Surface& surface = scene.surfaces[s];
    glStencilFunc(GL_ALWAYS, static_cast<GLint>(s + 1), 0xff);
    const Eigen::Vector3d n = surface.normal;
    const Eigen::Vector3d center =
        settings_.surface_center - n.dot(settings_.surface_center - surface.point) * n;
    const Eigen::Vector3d belt = beltDirection(surface);
    const bool is_belt = belt.norm() > 0;
    // u along the belt's motion (or t1), w across it
    const Eigen::Vector3d u = is_belt ? belt : Eigen::Vector3d(surface.tangents().col(0));
    const Eigen::Vector3d w = n.cross(u);
    const double half_u = settings_.surface_extent, half_w = is_belt ? settings_.belt_width / 2 : settings_.surface_extent;
    // texture coordinates: world distance / tile, shifted by the belt's travel
    const double shift = s < frame.surface_shift.size() ? frame.surface_shift[s] : 0.0;
    const double tile = settings_.tile;
    glBindTexture(GL_TEXTURE_2D, is_belt ? gl_->stripes : gl_->checker);
    glColor4f(1, 1, 1, 1);
    // a grid of cells, not one quad: fixed-function fog and lighting are per vertex
    constexpr int kCells = 64;
    glNormal3d(n.x(), n.y(), n.z());
    for (int j = 0; j < kCells; ++j) {
      glBegin(GL_QUAD_STRIP);
      for (int i = 0; i <= kCells; ++i)
        for (int dj = 1; dj >= 0; --dj) {
          const double a = -1 + 2.0 * i / kCells, b = -1 + 2.0 * (j + dj) / kCells;
          const Eigen::Vector3d p = center + a * half_u * u + b * half_w * w;
          const double tu = (p - surface.point).dot(u), tw = (p - surface.point).dot(w);
          glTexCoord2d((tu - shift) / tile, tw / tile);
          glVertex3d(p.x(), p.y(), p.z());
        }
      glEnd();
    }
    if (is_belt) {  // the belt's sides, a slab of thickness tile/3 below its surface
      glDisable(GL_TEXTURE_2D);
      glColor4f(0.25f, 0.26f, 0.28f, 1);
      const double depth = tile / 3;
      glBegin(GL_QUADS);
      for (double side : {-1.0, 1.0}) {
        const Eigen::Vector3d out = side * w;
        glNormal3d(out.x(), out.y(), out.z());
        for (int corner = 0; corner < 4; ++corner) {
          const double a = (corner == 0 || corner == 3) ? -1 : 1, down = corner < 2 ? 0 : depth;
          const Eigen::Vector3d p = center + a * half_u * u + side * half_w * w - down * n;
          glVertex3d(p.x(), p.y(), p.z());
        }
      }
      glEnd();
      glEnable(GL_TEXTURE_2D);
    }
  }
  glDisable(GL_TEXTURE_2D);
  glDisable(GL_POLYGON_OFFSET_FILL);
}

// Planar shadows: the shapes flattened onto each surface along the key light, darkening each
// stencil-marked pixel once (the stencil is cleared where a shadow is drawn).
void Renderer::drawShadows(const FrameContent& frame, const Eigen::Vector3d& light) {
  const scene::Scene& scene = geometry_.scene();
  const auto& shapes = geometry_.shapes();
  const auto& meshes = geometry_.meshes();
  glDisable(GL_LIGHTING);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
  glStencilOp(GL_KEEP, GL_KEEP, GL_ZERO);
  glColor4f(0.05f, 0.05f, 0.08f, 0.38f);
  for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
    const scene::Surface& surface = scene.surfaces[s];
    if (surface.normal.dot(light) <= 1e-3) continue;  // lit from behind: no shadow on it
    glStencilFunc(GL_EQUAL, static_cast<GLint>(s + 1), 0xff);
    const Eigen::Matrix4d S = shadowMatrix(surface.normal, surface.point, light);
    for (std::size_t i = 0; i < shapes.size(); ++i) {
      glPushMatrix();
      multMatrix(S * shapeMatrix(frame.pose.X_WG[i], shapes[i].scale));
      drawMesh(meshes[shapes[i].mesh]);
      glPopMatrix();
    }
  }
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glEnable(GL_LIGHTING);
}

// The posed shapes, lit.
void Renderer::drawModel(const FrameContent& frame) {
  const auto& shapes = geometry_.shapes();
  const auto& meshes = geometry_.meshes();
  const GLfloat body_specular[] = {0.4f, 0.4f, 0.4f, 1};
  glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, body_specular);
  glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, 40);
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    glPushMatrix();
    multMatrix(shapeMatrix(frame.pose.X_WG[i], shapes[i].scale));
    const auto& c = shapes[i].rgba;
    glColor4f(c[0], c[1], c[2], 1);
    drawMesh(meshes[shapes[i].mesh]);
    glPopMatrix();
  }
}

// Contact-force arrows: a cylinder shaft and a cone head from the contact point.
void Renderer::drawArrows(const FrameContent& frame) {
  glColor4f(0.1f, 0.65f, 0.25f, 1);
  const double r = settings_.arrow_radius;
  for (const FrameContent::Arrow& arrow : frame.arrows) {
    const double length = arrow.vector.norm();
    if (length < 2 * r) continue;
    const double head = std::min(0.4 * length, 4 * r);
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), arrow.vector).toRotationMatrix();
    X.translation() = arrow.tail;
    glPushMatrix();
    multMatrix(X.matrix());
    glPushMatrix();
    glTranslated(0, 0, (length - head) / 2);
    glScaled(r, r, length - head);
    drawMesh(gl_->cylinder);
    glPopMatrix();
    glTranslated(0, 0, length - head);
    glScaled(2.2 * r, 2.2 * r, head);
    drawMesh(gl_->cone);
    glPopMatrix();
  }
}

// Impulse markers: an expanding ring and a shrinking star in the surface's plane, fading with age.
void Renderer::drawMarkers(const FrameContent& frame) {
  glDisable(GL_LIGHTING);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  for (const FrameContent::Marker& m : frame.markers) {
    const double alpha = std::clamp(1 - m.age, 0.0, 1.0);
    const Eigen::Vector3d n = m.normal.normalized();
    const Eigen::Vector3d a = (std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY()).cross(n).normalized();
    const Eigen::Vector3d b = n.cross(a);
    const Eigen::Vector3d c = m.center + 0.002 * m.size * n;
    // expanding ring
    const double outer = m.size * (0.35 + 0.65 * m.age), inner = outer * 0.8;
    glColor4f(1.0f, 0.55f, 0.05f, float(alpha));
    glBegin(GL_TRIANGLE_STRIP);
    for (int i = 0; i <= 48; ++i) {
      const double t = 2 * std::numbers::pi * i / 48;
      const Eigen::Vector3d d = std::cos(t) * a + std::sin(t) * b;
      const Eigen::Vector3d p = c + outer * d, q = c + inner * d;
      glVertex3d(p.x(), p.y(), p.z());
      glVertex3d(q.x(), q.y(), q.z());
    }
    glEnd();
    // star: eight spikes in the plane and one along the normal, shrinking with age
    glColor4f(1.0f, 0.85f, 0.1f, float(alpha));
    const double spike = m.size * (1 - 0.5 * m.age), width = 0.08 * m.size;
    glBegin(GL_TRIANGLES);
    for (int i = 0; i < 8; ++i) {
      const double t = 2 * std::numbers::pi * i / 8;
      const Eigen::Vector3d d = std::cos(t) * a + std::sin(t) * b, side = n.cross(d);
      for (const Eigen::Vector3d& up : {Eigen::Vector3d::Zero().eval(), (0.5 * spike * n).eval()}) {
        const Eigen::Vector3d dir = up.norm() > 0 ? (d + n).normalized() : d;
        const Eigen::Vector3d s = (up.norm() > 0 ? dir.cross(n).normalized() : side);
        const Eigen::Vector3d tip = c + spike * dir, l = c + width * s, rr = c - width * s;
        glVertex3d(l.x(), l.y(), l.z());
        glVertex3d(rr.x(), rr.y(), rr.z());
        glVertex3d(tip.x(), tip.y(), tip.z());
      }
    }
    glEnd();
  }
  glDisable(GL_BLEND);
  glEnable(GL_LIGHTING);
}

// RGBA (supersampled) -> RGB, averaging supersample × supersample blocks.
void Renderer::downsample() {
  const int k = settings_.supersample, W = settings_.width, H = settings_.height;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int ch = 0; ch < 3; ++ch) {
        int sum = 0;
        for (int j = 0; j < k; ++j)
          for (int i = 0; i < k; ++i)
            sum += gl_->rgba[((static_cast<std::size_t>(y) * k + j) * gl_->width + x * k + i) * 4 + ch];
        rgb_[(static_cast<std::size_t>(y) * W + x) * 3 + ch] = static_cast<std::uint8_t>((sum + k * k / 2) / (k * k));
      }
}

}  // namespace saltus::render
