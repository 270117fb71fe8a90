#include "figure/rig.h"

#include <map>

namespace arview::figure {
namespace {

// ---------------------------------------------------------------------------------------------
// The skin. A Surface collects vertices with two bone influences and triangles tagged with a
// material; its normals are averaged over all of its triangles before it is split into one
// mesh per material, so that a colour boundary (a sleeve's end) is not a shading seam.

enum MaterialSlot { kSkin, kShirt, kTrousers, kShoes, kHair, kEyes, kLips, kEyeWhite, kIris, kMouth, kMaterialCount };

struct MaterialSpec {
  const char* name;
  Eigen::Vector4f color;
};

const MaterialSpec kMaterials[kMaterialCount] = {
    {"skin", {0.87f, 0.67f, 0.53f, 1}},     {"shirt", {0.80f, 0.24f, 0.20f, 1}}, {"trousers", {0.17f, 0.22f, 0.38f, 1}},
    {"shoes", {0.88f, 0.88f, 0.85f, 1}},    {"hair", {0.24f, 0.14f, 0.08f, 1}},  {"eyes", {0.07f, 0.05f, 0.05f, 1}},
    {"lips", {0.72f, 0.36f, 0.36f, 1}},     {"eye_white", {0.96f, 0.95f, 0.92f, 1}}, {"iris", {0.22f, 0.40f, 0.55f, 1}},
    {"mouth", {0.30f, 0.08f, 0.09f, 1}},
};

struct Influence {
  int a = 0, b = 0;
  double wb = 0;  // weight of b; a gets 1 − wb
};

struct Surface {
  std::string name;
  std::vector<Vector3d> positions;
  std::vector<Influence> influences;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<int> material;  // per triangle

  std::uint32_t Vertex(const Vector3d& p, const Influence& inf) {
    positions.push_back(p);
    influences.push_back(inf);
    return static_cast<std::uint32_t>(positions.size() - 1);
  }
  void Triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, int slot) {
    triangles.push_back({a, b, c});
    material.push_back(slot);
  }
};

// Cross-section frame of a tube running along `dir`: (side, depth, dir) right-handed, side as
// close to the model's +X as the direction allows (so rx is the left-right radius).
void TubeFrame(const Vector3d& dir, Vector3d& side, Vector3d& depth) {
  Vector3d s = Vector3d::UnitX() - Vector3d::UnitX().dot(dir) * dir;
  if (s.norm() < 1e-3) s = Vector3d::UnitY() - Vector3d::UnitY().dot(dir) * dir;
  side = s.normalized();
  depth = dir.cross(side);
}

struct TubeNode {
  Vector3d p;
  double rx, rz;  // radii across (left-right) and in depth
  int joint;      // the bone that moves the tube from this node on
};

struct TubeOptions {
  int sides = 14;
  double spacing = 0.025;  // between rings along the axis, metres
  double cap_start = 0.03, cap_end = 0.03;
  int cap_rings = 4;
  double band = 0.04;  // half-width of the blend between two bones around a node
  std::function<int(double along, const Vector3d& centre)> material = [](double, const Vector3d&) { return kSkin; };
};

// A smooth generalised cylinder through `nodes` with rounded ends.
void AddTube(Surface& s, const std::vector<TubeNode>& nodes, const TubeOptions& o) {
  const int n = static_cast<int>(nodes.size());
  std::vector<double> at(n, 0.0);
  std::vector<Vector3d> seg_dir(n - 1);
  for (int k = 0; k + 1 < n; ++k) {
    seg_dir[k] = (nodes[k + 1].p - nodes[k].p).normalized();
    at[k + 1] = at[k] + (nodes[k + 1].p - nodes[k].p).norm();
  }
  const double length = at.back();
  auto segment_of = [&](double u) {
    int k = 0;
    while (k + 2 < n && u > at[k + 1]) ++k;
    return k;
  };
  auto direction = [&](double u) {
    const int k = segment_of(u);
    Vector3d d = seg_dir[k];
    // Turn smoothly through a node so that rings do not fold at a bend.
    if (k + 1 < n - 1 && u > at[k + 1] - o.band) d = d + (seg_dir[k + 1] - d) * SmoothStep((u - at[k + 1] + o.band) / (2 * o.band)) * 0.5;
    if (k > 0 && u < at[k] + o.band) d = d + (seg_dir[k - 1] - d) * (1 - SmoothStep((u - at[k] + o.band) / (2 * o.band))) * 0.5;
    return d.normalized();
  };
  auto centre = [&](double u) {
    if (u <= 0) return Vector3d(nodes[0].p + seg_dir[0] * u);
    if (u >= length) return Vector3d(nodes[n - 1].p + seg_dir[n - 2] * (u - length));
    const int k = segment_of(u);
    return Vector3d(nodes[k].p + seg_dir[k] * (u - at[k]));
  };
  auto radii = [&](double u) {
    if (u <= 0) return Eigen::Vector2d(nodes[0].rx, nodes[0].rz);
    if (u >= length) return Eigen::Vector2d(nodes[n - 1].rx, nodes[n - 1].rz);
    const int k = segment_of(u);
    const double f = SmoothStep((u - at[k]) / (at[k + 1] - at[k]));
    return Eigen::Vector2d(nodes[k].rx + (nodes[k + 1].rx - nodes[k].rx) * f, nodes[k].rz + (nodes[k + 1].rz - nodes[k].rz) * f);
  };
  // Node k's joint owns the tube from node k on; around an inner node the two owners blend.
  auto influence = [&](double u) {
    int owner = 0;
    for (int k = 0; k < n; ++k)
      if (u >= at[k]) owner = k;
    Influence inf{nodes[owner].joint, nodes[owner].joint, 0};
    for (int k = 1; k < n; ++k) {
      if (std::abs(u - at[k]) < o.band && nodes[k - 1].joint != nodes[k].joint) {
        const int before = nodes[std::max(0, k - 1)].joint;
        inf = {before, nodes[k].joint, SmoothStep((u - at[k] + o.band) / (2 * o.band))};
      }
    }
    return inf;
  };

  // Ring positions along the axis: the start cap, the body, the end cap.
  struct Ring {
    double u, scale;
  };
  std::vector<Ring> rings;
  for (int i = o.cap_rings - 1; i >= 1; --i) {
    const double a = (kPi / 2) * i / o.cap_rings;
    rings.push_back({-o.cap_start * std::sin(a), std::cos(a)});
  }
  const int body = std::max(1, static_cast<int>(std::ceil(length / o.spacing)));
  for (int i = 0; i <= body; ++i) rings.push_back({length * i / body, 1.0});
  for (int i = 1; i < o.cap_rings; ++i) {
    const double a = (kPi / 2) * i / o.cap_rings;
    rings.push_back({length + o.cap_end * std::sin(a), std::cos(a)});
  }

  std::vector<std::uint32_t> first(rings.size());
  for (std::size_t r = 0; r < rings.size(); ++r) {
    const double u = rings[r].u;
    Vector3d side, depth;
    TubeFrame(direction(u), side, depth);
    const Eigen::Vector2d rad = radii(u) * rings[r].scale;
    const Vector3d c = centre(u);
    const Influence inf = influence(u);
    first[r] = static_cast<std::uint32_t>(s.positions.size());
    for (int a = 0; a < o.sides; ++a) {
      const double angle = 2 * kPi * a / o.sides;
      s.Vertex(c + side * rad.x() * std::cos(angle) + depth * rad.y() * std::sin(angle), inf);
    }
  }
  for (std::size_t r = 0; r + 1 < rings.size(); ++r) {
    const double mid = 0.5 * (rings[r].u + rings[r + 1].u);
    const int slot = o.material(mid, centre(mid));
    for (int a = 0; a < o.sides; ++a) {
      const std::uint32_t v00 = first[r] + a, v01 = first[r] + (a + 1) % o.sides;
      const std::uint32_t v10 = first[r + 1] + a, v11 = first[r + 1] + (a + 1) % o.sides;
      s.Triangle(v00, v01, v10, slot);
      s.Triangle(v01, v11, v10, slot);
    }
  }
  const std::uint32_t start_pole = s.Vertex(centre(-o.cap_start), influence(-o.cap_start));
  const std::uint32_t end_pole = s.Vertex(centre(length + o.cap_end), influence(length + o.cap_end));
  const int start_slot = o.material(-o.cap_start, centre(-o.cap_start));
  const int end_slot = o.material(length + o.cap_end, centre(length + o.cap_end));
  const std::uint32_t last = first.back();
  for (int a = 0; a < o.sides; ++a) {
    const std::uint32_t b = (a + 1) % o.sides;
    s.Triangle(start_pole, first[0] + b, first[0] + a, start_slot);
    s.Triangle(last + a, last + b, end_pole, end_slot);
  }
}

struct EllipsoidSpec {
  Vector3d centre;
  Eigen::Matrix3d axes;  // columns: the three semi-axes (any lengths, right-handed or not)
  int stacks = 10, slices = 16;
  int slot = kSkin;
  std::function<Influence(const Vector3d&)> influence;
  std::function<bool(const Vector3d&)> keep;  // triangles whose three corners pass; all if empty
  std::function<int(const Vector3d&)> slot_at;  // a triangle's material from its centroid; `slot` if empty
};

void AddEllipsoid(Surface& s, const EllipsoidSpec& e) {
  // Poles on the third axis; rings of `slices` vertices in between.
  auto point = [&](double theta, double phi) {
    return Vector3d(e.centre + e.axes * Vector3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)));
  };
  auto vertex = [&](const Vector3d& p) { return s.Vertex(p, e.influence(p)); };
  const bool flip = e.axes.determinant() < 0;
  auto triangle = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (e.keep && !(e.keep(s.positions[a]) && e.keep(s.positions[b]) && e.keep(s.positions[c]))) return;
    const int slot = e.slot_at ? e.slot_at((s.positions[a] + s.positions[b] + s.positions[c]) / 3) : e.slot;
    if (flip) s.Triangle(a, c, b, slot);
    else s.Triangle(a, b, c, slot);
  };
  const std::uint32_t north = vertex(point(0, 0));
  std::vector<std::uint32_t> ring_start;
  for (int i = 1; i < e.stacks; ++i) {
    ring_start.push_back(static_cast<std::uint32_t>(s.positions.size()));
    for (int j = 0; j < e.slices; ++j) vertex(point(kPi * i / e.stacks, 2 * kPi * j / e.slices));
  }
  const std::uint32_t south = vertex(point(kPi, 0));
  const int rings = static_cast<int>(ring_start.size());
  for (int j = 0; j < e.slices; ++j) {
    const int k = (j + 1) % e.slices;
    // (θ, φ), (θ + dθ, φ), (θ, φ + dφ) winds outward for a right-handed `axes`.
    triangle(north, ring_start[0] + j, ring_start[0] + k);
    for (int i = 0; i + 1 < rings; ++i) {
      triangle(ring_start[i] + j, ring_start[i + 1] + j, ring_start[i] + k);
      triangle(ring_start[i] + k, ring_start[i + 1] + j, ring_start[i + 1] + k);
    }
    triangle(ring_start[rings - 1] + j, south, ring_start[rings - 1] + k);
  }
}

Influence Rigid(int joint) { return {joint, joint, 0}; }

Eigen::Matrix3d Axes(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  Eigen::Matrix3d m;
  m << a, b, c;
  return m;
}

void AddTorso(Surface& s, const Rig& r) {
  TubeOptions o;
  o.sides = 20;
  o.cap_start = 0.07;
  o.cap_end = 0.06;
  o.band = 0.05;
  o.material = [](double, const Vector3d& c) { return c.y() < 0.935 ? kTrousers : kShirt; };
  AddTube(s,
          {{{0, 0.86, 0}, 0.150, 0.105, r.Index("Hips")},
           {{0, 0.96, 0}, 0.165, 0.110, r.Index("Hips")},
           {{0, 1.06, 0.005}, 0.140, 0.100, r.Index("Spine")},
           {{0, 1.18, 0.01}, 0.150, 0.108, r.Index("Spine1")},
           {{0, 1.30, 0.005}, 0.170, 0.112, r.Index("Spine2")},
           {{0, 1.39, 0}, 0.185, 0.100, r.Index("Spine2")}},
          o);
}

void AddNeck(Surface& s, const Rig& r) {
  TubeOptions o;
  o.sides = 14;
  o.spacing = 0.02;
  o.cap_start = o.cap_end = 0.02;
  o.band = 0.03;
  AddTube(s,
          {{{0, 1.38, -0.005}, 0.060, 0.056, r.Index("Spine2")},
           {{0, 1.45, 0}, 0.055, 0.052, r.Index("Neck")},
           {{0, 1.56, 0.005}, 0.052, 0.052, r.Index("Head")}},
          o);
}

void AddHead(Surface& s, const Rig& r) {
  const int head = r.Index("Head");
  const Vector3d c = HeadCentre(r);
  EllipsoidSpec skull;
  skull.centre = c;
  skull.axes = Axes({0.080, 0, 0}, {0, 0, 0.098}, {0, 0.105, 0});  // poles on y: x, z, y is left-handed
  skull.stacks = 14;
  skull.slices = 22;
  const int jaw = r.Index("Jaw");
  // The chin, below the mouth and in front, follows the jaw; the rest is the head's.
  skull.influence = [head, jaw, c](const Vector3d& p) {
    const Vector3d q = p - c;
    return Influence{head, jaw, SmoothStep((-0.052 - q.y()) / 0.02) * SmoothStep((q.z() - 0.03) / 0.04)};
  };
  AddEllipsoid(s, skull);
  skull.influence = [head](const Vector3d&) { return Rigid(head); };
  for (int side : {1, -1}) {  // ears
    EllipsoidSpec ear = skull;
    ear.centre = c + Vector3d(side * 0.078, 0.0, -0.005);
    ear.axes = Axes({0.012, 0, 0}, {0, 0, 0.020}, {0, 0.026, 0});
    ear.stacks = 5;
    ear.slices = 8;
    AddEllipsoid(s, ear);
  }
  EllipsoidSpec nose = skull;
  nose.centre = c + Vector3d(0, -0.012, 0.094);
  nose.axes = Axes({0.013, 0, 0}, {0, 0, 0.018}, {0, 0.024, 0});
  nose.stacks = 6;
  nose.slices = 10;
  AddEllipsoid(s, nose);
}

void AddFace(Surface& s, const Rig& r) {
  const Vector3d c = HeadCentre(r);
  auto feature = [&](const Vector3d& offset, const Vector3d& radii, int slot, int joint) {
    EllipsoidSpec e;
    e.centre = c + offset;
    e.axes = Axes({radii.x(), 0, 0}, {0, 0, radii.z()}, {0, radii.y(), 0});
    e.stacks = 5;
    e.slices = 10;
    e.slot = slot;
    e.influence = [joint](const Vector3d&) { return Rigid(joint); };
    AddEllipsoid(s, e);
  };
  for (int side : {1, -1}) feature({side * 0.033, 0.040, 0.080}, {0.021, 0.005, 0.008}, kHair, r.Index(Sided(side, "Brow")));
  // The lips meet at rest; the lower one opens with the jaw over the dark of the mouth.
  const int head = r.Index("Head"), jaw = r.Index("Jaw");
  feature({0, -0.046, 0.083}, {0.023, 0.0045, 0.009}, kLips, head);
  feature({0, -0.0545, 0.082}, {0.021, 0.005, 0.009}, kLips, jaw);
  feature({0, -0.050, 0.077}, {0.019, 0.008, 0.008}, kMouth, head);
}

// An eyeball (white, iris, pupil about its forward axis) and its two lids, shells a little
// larger than the eye that turn about its centre: the upper lid's edge 20° above the eye's
// axis, the lower's 30° below (on the shells' 10° rings, so the edges are straight); a blink
// turns the upper one down over the eye and the lower one up to meet it.
void AddEye(Surface& s, const Rig& r, int side) {
  const int eye = r.Index(Sided(side, "Eye"));
  const Vector3d centre = r.At(Sided(side, "Eye"));
  EllipsoidSpec ball;
  ball.centre = centre;
  ball.axes = Axes(Vector3d::UnitX() * kEyeRadius, Vector3d::UnitY() * kEyeRadius, Vector3d::UnitZ() * kEyeRadius);
  ball.stacks = 18;  // 10° rings from the front pole: the pupil one ring, the iris three
  ball.slices = 16;
  ball.influence = [eye](const Vector3d&) { return Rigid(eye); };
  ball.slot_at = [centre](const Vector3d& p) {
    const double from_axis = std::acos(std::clamp((p - centre).normalized().z(), -1.0, 1.0)) * 180 / kPi;
    return from_axis < 10 ? kEyes : from_axis < 30 ? kIris : kEyeWhite;
  };
  AddEllipsoid(s, ball);
  const double lid_radius = kEyeRadius * 1.07;
  for (const char* lid : {"UpperLid", "LowerLid"}) {
    const bool upper = lid[0] == 'U';
    const int joint = r.Index(Sided(side, lid));
    EllipsoidSpec shell;
    shell.centre = centre;
    // Poles on y, so that the rings run level and a lid's edge is one of them.
    shell.axes = Axes(Vector3d::UnitX() * lid_radius, Vector3d::UnitZ() * lid_radius, Vector3d::UnitY() * lid_radius);
    shell.stacks = 18;
    shell.slices = 16;
    shell.influence = [joint](const Vector3d&) { return Rigid(joint); };
    const double edge = lid_radius * std::sin(Rad(upper ? 20 : -30));
    shell.keep = [centre, edge, upper](const Vector3d& p) { return upper ? p.y() - centre.y() > edge - 1e-6 : p.y() - centre.y() < edge + 1e-6; };
    AddEllipsoid(s, shell);
  }
}

void AddHair(Surface& s, const Rig& r) {
  const int head = r.Index("Head");
  const Vector3d c = HeadCentre(r);
  EllipsoidSpec hair;
  hair.centre = c + Vector3d(0, 0.014, -0.008);
  hair.axes = Axes({0.089, 0, 0}, {0, 0, 0.104}, {0, 0.110, 0});
  hair.stacks = 14;
  hair.slices = 22;
  hair.slot = kHair;
  hair.influence = [head](const Vector3d&) { return Rigid(head); };
  // Down the back of the head, above the ears at the sides, a fringe at the front.
  hair.keep = [c](const Vector3d& p) {
    const Vector3d q = p - c;
    if (q.z() < -0.03) return q.y() > -0.075;
    if (q.z() < 0.045) return q.y() > 0.005;
    return q.y() > 0.058;
  };
  AddEllipsoid(s, hair);
}

void AddArm(Surface& s, const Rig& r, int side) {
  TubeOptions o;
  o.sides = 14;
  o.cap_start = 0.05;
  o.cap_end = 0.02;
  o.band = 0.045;
  o.material = [](double along, const Vector3d&) { return along < 0.13 ? kShirt : kSkin; };
  AddTube(s,
          {{r.At(Sided(side, "Arm")), 0.052, 0.056, r.Index(Sided(side, "Arm"))},
           {r.At(Sided(side, "ForeArm")), 0.040, 0.043, r.Index(Sided(side, "ForeArm"))},
           {r.At(Sided(side, "Hand")), 0.031, 0.024, r.Index(Sided(side, "Hand"))}},
          o);
}

void AddHand(Surface& s, const Rig& r, int side) {
  const int hand = r.Index(Sided(side, "Hand"));
  const Vector3d d = ArmDirection(side);
  Vector3d across, forward;
  TubeFrame(d, across, forward);
  EllipsoidSpec mitten;
  mitten.centre = r.At(Sided(side, "Hand")) + 0.072 * d;
  mitten.axes = Axes(across * 0.021, forward * 0.043, d * 0.078);
  mitten.stacks = 8;
  mitten.slices = 12;
  mitten.influence = [hand](const Vector3d&) { return Rigid(hand); };
  AddEllipsoid(s, mitten);
  TubeOptions o;
  o.sides = 8;
  o.spacing = 0.02;
  o.cap_start = 0.01;
  o.cap_end = 0.012;
  o.cap_rings = 3;
  const int thumb = r.Index(Sided(side, "HandThumb1"));
  const Vector3d base = r.At(Sided(side, "HandThumb1"));
  const Vector3d tip = base + 0.05 * (0.75 * d + 0.55 * Vector3d::UnitZ() - 0.2 * side * Vector3d::UnitX()).normalized();
  AddTube(s, {{base, 0.012, 0.011, thumb}, {tip, 0.010, 0.009, thumb}}, o);
}

void AddLeg(Surface& s, const Rig& r, int side) {
  TubeOptions o;
  o.sides = 14;
  o.cap_start = 0.06;
  o.cap_end = 0.03;
  o.band = 0.05;
  o.material = [](double, const Vector3d&) { return kTrousers; };
  const Vector3d hip = r.At(Sided(side, "UpLeg")), knee = r.At(Sided(side, "Leg")), ankle = r.At(Sided(side, "Foot"));
  const int up = r.Index(Sided(side, "UpLeg")), leg = r.Index(Sided(side, "Leg")), foot = r.Index(Sided(side, "Foot"));
  AddTube(s,
          {{hip, 0.085, 0.088, up},
           {hip + 0.45 * (knee - hip), 0.071, 0.074, up},
           {knee, 0.054, 0.056, leg},
           {knee + 0.4 * (ankle - knee), 0.055, 0.060, leg},
           {ankle, 0.038, 0.040, foot}},
          o);
}

void AddShoe(Surface& s, const Rig& r, int side) {
  const int foot = r.Index(Sided(side, "Foot")), toe = r.Index(Sided(side, "ToeBase"));
  EllipsoidSpec shoe;
  shoe.centre = Vector3d(side * 0.09, 0.045, 0.055);
  shoe.axes = Axes({0.05, 0, 0}, {0, 0.048, 0}, {0, 0, 0.13});
  shoe.stacks = 12;
  shoe.slices = 14;
  shoe.slot = kShoes;
  shoe.influence = [foot, toe](const Vector3d& p) { return Influence{foot, toe, SmoothStep((p.z() - 0.08) / 0.06)}; };
  AddEllipsoid(s, shoe);
}

std::vector<Vector3f> SmoothNormals(const Surface& s) {
  std::vector<Vector3d> sum(s.positions.size(), Vector3d::Zero());
  for (const auto& t : s.triangles) {
    const Vector3d n = (s.positions[t[1]] - s.positions[t[0]]).cross(s.positions[t[2]] - s.positions[t[0]]);
    for (std::uint32_t v : t) sum[v] += n;  // area-weighted
  }
  std::vector<Vector3f> normals(sum.size());
  for (std::size_t v = 0; v < sum.size(); ++v)
    normals[v] = sum[v].norm() > 0 ? Vector3f(sum[v].normalized().cast<float>()) : Vector3f::UnitY();
  return normals;
}

// One mesh per material of the surface.
void EmitMeshes(const Surface& s, anim::Character& c) {
  const std::vector<Vector3f> normals = SmoothNormals(s);
  for (int slot = 0; slot < kMaterialCount; ++slot) {
    anim::Mesh mesh;
    mesh.name = s.name + "_" + kMaterials[slot].name;
    mesh.material = slot;
    std::map<std::uint32_t, std::uint32_t> remap;
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
      if (s.material[t] != slot) continue;
      for (std::uint32_t v : s.triangles[t]) {
        auto [it, added] = remap.emplace(v, static_cast<std::uint32_t>(mesh.positions.size()));
        if (added) {
          const Influence& inf = s.influences[v];
          mesh.positions.push_back(s.positions[v].cast<float>());
          mesh.normals.push_back(normals[v]);
          std::array<std::uint16_t, 4> joints{static_cast<std::uint16_t>(inf.a), static_cast<std::uint16_t>(inf.b), 0, 0};
          Eigen::Vector4f weights(static_cast<float>(1 - inf.wb), static_cast<float>(inf.wb), 0, 0);
          if (inf.a == inf.b) weights = Eigen::Vector4f(1, 0, 0, 0);
          mesh.joints.push_back(joints);
          mesh.weights.push_back(weights);
        }
        mesh.indices.push_back(it->second);
      }
    }
    if (!mesh.indices.empty()) c.meshes.push_back(std::move(mesh));
  }
}

}  // namespace

void AddSkin(const Rig& rig, anim::Character& character) {
  for (const MaterialSpec& m : kMaterials) character.materials.push_back({m.name, m.color, -1});

  std::vector<Surface> surfaces;
  auto surface = [&](const std::string& name) -> Surface& {
    surfaces.push_back({});
    surfaces.back().name = name;
    return surfaces.back();
  };
  AddTorso(surface("torso"), rig);
  AddNeck(surface("neck"), rig);
  AddHead(surface("head"), rig);
  AddFace(surface("face"), rig);
  for (int side : {1, -1}) AddEye(surface(Sided(side, "Eye")), rig, side);
  AddHair(surface("hair"), rig);
  for (int side : {1, -1}) {
    const std::string s = Sided(side, "");
    AddArm(surface(s + "Arm"), rig, side);
    AddHand(surface(s + "Hand"), rig, side);
    AddLeg(surface(s + "Leg"), rig, side);
    AddShoe(surface(s + "Shoe"), rig, side);
  }
  for (const Surface& s : surfaces) EmitMeshes(s, character);
}

}  // namespace arview::figure
