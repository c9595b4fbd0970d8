#!/usr/bin/python3
"""Axial-turbine distributor (guide vanes) of a Kaplan-type water turbine, written in the
ANSYS TurboGrid / CFX-BladeGen layout (BladeGen.inf + hub.curve, shroud.curve,
profile.curve) with the same conventions as ../rotor37/turbogrid.

Run:  /usr/bin/python3 generate_distributor.py      (numpy only; deterministic; writes the
      four files and nothing else next to this script, overwriting them)

Design (all lengths in metres, files in unit M; machine axis = Z, flow in +Z):

  blades            Z = 16 guide vanes (one blade set, pitch 22.5 deg)
  annulus           cylindrical in the vane region |z| <= 0.20:  r_hub = 0.45, r_shroud = 1.00
                    (span 0.55, hub/tip ratio 0.45); contours from z = -0.55 to z = +0.70
  hub radius        r_h(z) = 0.45 - 0.05*S((-0.20 - z)/0.30) + 0.02*S((z - 0.20)/0.40)
                    0.40 at z <= -0.50 (nose fairing), 0.45 on |z| <= 0.20, 0.47 at z >= 0.60
  shroud radius     r_s(z) = 1.00 + 0.04*S((-0.20 - z)/0.30) - 0.05*S((z - 0.20)/0.40)
                    1.04 at z <= -0.50, 1.00 on |z| <= 0.20, 0.95 at z >= 0.60
                    S(t) = 0 (t <= 0), 10t^3 - 15t^4 + 6t^5 (0 < t < 1), 1 (t >= 1)  (C2 ramp)
                    -> the annulus converges all the way: A_in/A_vanes/A_out =
                       0.9216 pi / 0.7975 pi / 0.6816 pi m^2
  sections          6, "Profile k at 20(k-1) %", k = 1..6, each on a cylinder
                    r_k = 0.45 + 0.11 (k-1) = 0.45 0.56 0.67 0.78 0.89 1.00:
                    section 1 lies exactly on the hub, section 6 exactly on the shroud
                    (as in Rotor 37), spanwise fraction s = (k-1)/5
  NACA 4-digit      camber m = 0.04 - 0.02 s, camber position p = 0.4, thickness t = 0.12 - 0.02 s
                    (NACA 4412 at the hub ... 2410 at the shroud, values linear in s)
  trailing edge     rounded as Rotor 37's: the NACA thickness law is cut at x = 0.97 (nominal
                    chord) and continued by the circle tangent to it, centred on the camber
                    line (TE radius 0.54 % of the nominal chord at t = 0.12)
  chord             c = 0.30 + 0.12 s  (0.30 at the hub ... 0.42 at the shroud), measured from
                    the leading-edge tip (camber-line start) to the trailing-edge tip
                    (camber-line end); the NACA section is scaled and rotated so that
                    this chord has exactly length c and angle gamma
  stagger           gamma = 50 - 15 s deg (50 at the hub ... 35 at the shroud), angle of the
                    chord from the +Z axis; the chord runs towards -theta (the vanes give the
                    water a swirl in -theta, i.e. the runner turns about -Z, like Rotor 37);
                    more turning at the hub, as a free-vortex (r c_u = const) design wants
  solidity          c Z / (2 pi r) = 1.70 (hub) 1.47 1.32 1.21 1.13 1.07 (shroud); the vanes
                    overlap in the axial view but never touch: the smallest distance to the
                    periodic neighbour is 0.081 m at the hub, 0.287 m at the shroud
  stacking          chord mid-points on the radial line theta = 0, z = 0
  wrapping          section point (m, u) of the 2-D design plane -> x = r cos(u/r),
                    y = r sin(u/r), z = m (exact isometry of the cylinder)
  points            301 per section, closed (point 301 = point 1), 151 per side, spaced by a
                    curvature-based size field (dense on the round LE and TE, ~20 points on
                    each side of the TE circle, every segment turning < 4.5 deg, largest
                    segment ~1.2 % of the chord, neighbour length ratio < 1.15)

Conventions copied from Rotor 37 (../rotor37/turbogrid): rows "X Y Z" printed "%#16.9g"
three times; every section after "# Profile k at s%" and followed by one empty line;
point 1 = leading-edge tip (camber-line start), the loop runs first along the suction side
(the +theta side for both machines) to the trailing-edge tip (point 151), then back along
the pressure side to the leading edge; in the unwrapped (z, r theta) plane it runs clockwise
(negative signed area). Hub and shroud contours run in +Z; through the blade they follow
the camber line of the hub (shroud) section, from its LE tip to its TE tip, upstream and
downstream of it they keep the theta of that tip, so they contain the LE and TE tips of
section 1 (6) exactly (Rotor 37 repeats those two points; here they appear once).
"""

import math
import os

import numpy as np

# ------------------------------------------------------------------------------------------
# Parameters
BLADE_COUNT = 16
UNITS = "M"  # unit of the files; the lengths below are metres either way
METRES_PER_UNIT = {"M": 1.0, "CM": 0.01, "MM": 0.001}

R_HUB = 0.45
R_SHROUD = 1.00
Z_IN, Z_OUT = -0.55, 0.70           # axial extent of the hub and shroud contours
Z_CYL = 0.20                        # contours are cylinders on |z| <= Z_CYL
L_UP, L_DOWN = 0.30, 0.40           # lengths of the upstream and downstream ramps
DR_HUB_UP, DR_HUB_DOWN = -0.05, +0.02       # hub radius change upstream / downstream
DR_SHROUD_UP, DR_SHROUD_DOWN = +0.04, -0.05  # shroud radius change upstream / downstream

SPANS = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0]      # spanwise fractions of the sections
CAMBER_HUB, CAMBER_TIP = 0.04, 0.02         # NACA m
CAMBER_POS = 0.4                            # NACA p
THICK_HUB, THICK_TIP = 0.12, 0.10           # NACA t
X_TE_CUT = 0.97                             # thickness law cut here, then rounded
CHORD_HUB, CHORD_TIP = 0.30, 0.42           # [m]
STAGGER_HUB, STAGGER_TIP = 50.0, 35.0       # [deg] from the axis
Z_STACK = 0.0                               # axial position of the chord mid-points
POINTS_PER_SIDE = 151                       # 2 * 151 - 1 = 301 points per closed section
H_MAX = 0.01           # point spacing: largest segment, in nominal chords (before scaling)
TURN_MAX = 0.06        # ... segment length <= TURN_MAX / curvature (turning <= 0.06 rad)
GRADATION = 0.1        # ... segment length grows by at most 0.1 per unit arc length
SIZE_SAMPLES = 40001   # samples of the size field along one side

CONTOUR_UP, CONTOUR_BLADE, CONTOUR_DOWN = 50, 100, 60  # intervals -> 211 contour points


# ------------------------------------------------------------------------------------------
# Meridional contours
def ramp(t):
    """C2 smooth step: 0 for t <= 0, 1 for t >= 1."""
    t = np.clip(np.asarray(t, dtype=float), 0.0, 1.0)
    return t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)


def hub_radius(z):
    return (R_HUB + DR_HUB_UP * ramp((-Z_CYL - z) / L_UP)
            + DR_HUB_DOWN * ramp((z - Z_CYL) / L_DOWN))


def shroud_radius(z):
    return (R_SHROUD + DR_SHROUD_UP * ramp((-Z_CYL - z) / L_UP)
            + DR_SHROUD_DOWN * ramp((z - Z_CYL) / L_DOWN))


# ------------------------------------------------------------------------------------------
# NACA 4-digit section with a rounded trailing edge
def naca_camber(x, m, p):
    x = np.asarray(x, dtype=float)
    front = x < p
    yc = np.where(front, m / p**2 * (2 * p * x - x * x),
                  m / (1 - p)**2 * (1 - 2 * p + 2 * p * x - x * x))
    dyc = np.where(front, 2 * m / p**2 * (p - x), 2 * m / (1 - p)**2 * (p - x))
    return yc, dyc


def naca_thickness(x, t):
    x = np.asarray(x, dtype=float)
    sx = np.sqrt(x)
    yt = 5 * t * (0.2969 * sx - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1015 * x**4)
    with np.errstate(divide="ignore"):
        dyt = 5 * t * (0.2969 * 0.5 / sx - 0.1260 - 0.7032 * x + 0.8529 * x**2 - 0.4060 * x**3)
    return yt, dyt


class Section:
    """One vane section in the 2-D design plane (m = z, u = r theta) of its cylinder."""

    def __init__(self, s):
        self.s = s
        self.radius = R_HUB + s * (R_SHROUD - R_HUB)
        self.m = CAMBER_HUB + s * (CAMBER_TIP - CAMBER_HUB)
        self.p = CAMBER_POS
        self.t = THICK_HUB + s * (THICK_TIP - THICK_HUB)
        self.chord = CHORD_HUB + s * (CHORD_TIP - CHORD_HUB)
        self.stagger = STAGGER_HUB + s * (STAGGER_TIP - STAGGER_HUB)  # deg

        # Rounded trailing edge in thickness space: circle centred at (xc, 0), tangent to
        # the thickness law at X_TE_CUT.
        yt, dyt = naca_thickness(X_TE_CUT, self.t)
        self.xc = X_TE_CUT + yt * dyt
        self.rho = yt * math.sqrt(1 + dyt * dyt)
        self.phi_cut = math.atan2(yt, X_TE_CUT - self.xc)
        self.x_tip = self.xc + self.rho
        self.beta_cut = math.acos(1 - 2 * X_TE_CUT)

        # Normalised section -> chord frame: LE tip (0, 0), TE tip on the camber line.
        yc_tip, _ = naca_camber(self.x_tip, self.m, self.p)
        self.nominal_length = math.hypot(self.x_tip, float(yc_tip))  # chord / nominal chord
        self.delta = math.atan2(float(yc_tip), self.x_tip)
        g = math.radians(self.stagger)
        self.e = np.array([math.cos(g), -math.sin(g)])  # chord direction in (m, u)
        self.n = np.array([math.sin(g), math.cos(g)])   # suction side (+u side)
        self.mid = np.array([Z_STACK, 0.0])

    # normalised NACA coordinates (nominal chord 1) along one side, parameter q in [0, 2]
    def side_normalised(self, q, sign):
        q = np.asarray(q, dtype=float)
        front = q <= 1.0
        beta = np.minimum(q, 1.0) * self.beta_cut
        x_front = 0.5 * (1 - np.cos(beta))
        yt_front, _ = naca_thickness(x_front, self.t)
        phi = (2.0 - np.maximum(q, 1.0)) * self.phi_cut
        x = np.where(front, x_front, self.xc + self.rho * np.cos(phi))
        yt = np.where(front, yt_front, self.rho * np.sin(phi))
        yc, dyc = naca_camber(x, self.m, self.p)
        th = np.arctan(dyc)
        return np.stack([x - sign * yt * np.sin(th), yc + sign * yt * np.cos(th)], axis=-1)

    def to_design_plane(self, pts):
        """Normalised NACA coordinates -> (m, u) in metres."""
        c, sd = math.cos(-self.delta), math.sin(-self.delta)
        scale = self.chord / self.nominal_length
        xi = scale * (c * pts[..., 0] - sd * pts[..., 1])
        eta = scale * (sd * pts[..., 0] + c * pts[..., 1])
        return (self.mid + (xi[..., None] - 0.5 * self.chord) * self.e
                + eta[..., None] * self.n)

    def side(self, sign):
        """POINTS_PER_SIDE points from the LE tip to the TE tip, spaced by a size field:
        h(s) = min(H_MAX, TURN_MAX / curvature(s)), limited to grow by at most GRADATION per
        unit arc length (both ways), then scaled to exactly POINTS_PER_SIDE - 1 segments.
        This clusters points on the round leading and trailing edges (dense at both ends,
        like cosine spacing) while every segment turns by less than ~4.5 deg."""
        q = np.linspace(0.0, 2.0, 400001)
        pts = self.side_normalised(q, sign)
        arc = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
        s = np.linspace(0.0, arc[-1], SIZE_SAMPLES)
        ds = s[1] - s[0]
        dense = self.side_normalised(np.interp(s, arc, q), sign)
        direction = np.unwrap(np.arctan2(*np.diff(dense, axis=0).T[::-1]))
        curvature = np.abs(np.diff(direction)) / ds
        curvature = np.concatenate([[curvature[0]], curvature, [curvature[-1]]])
        h = np.minimum(H_MAX, TURN_MAX / np.maximum(curvature, 1e-12))
        for i in range(1, h.size):
            h[i] = min(h[i], h[i - 1] + GRADATION * ds)
        for i in range(h.size - 2, -1, -1):
            h[i] = min(h[i], h[i + 1] + GRADATION * ds)
        count = np.concatenate([[0.0], np.cumsum(0.5 * (1 / h[1:] + 1 / h[:-1]) * ds)])
        target = np.linspace(0.0, count[-1], POINTS_PER_SIDE)
        qi = np.interp(np.interp(target, count, s), arc, q)
        qi[0], qi[-1] = 0.0, 2.0
        return self.to_design_plane(self.side_normalised(qi, sign))

    def loop(self):
        """Closed loop: LE tip, suction side, TE tip, pressure side, LE tip again."""
        suction = self.side(+1.0)
        pressure = self.side(-1.0)
        return np.concatenate([suction, pressure[-2::-1]])

    def camber_line(self, count):
        x = np.linspace(0.0, self.x_tip, count)
        yc, _ = naca_camber(x, self.m, self.p)
        return self.to_design_plane(np.stack([x, yc], axis=-1))

    def wrap(self, mu):
        theta = mu[:, 1] / self.radius
        return np.stack([self.radius * np.cos(theta), self.radius * np.sin(theta), mu[:, 0]],
                        axis=-1)


# ------------------------------------------------------------------------------------------
# Files
def row(p):
    return "".join("%#16.9g" % (float(v) / METRES_PER_UNIT[UNITS] + 0.0) for v in p)


def contour(section, radius_function):
    """Meridional contour in +Z: constant theta upstream, the camber line of the section
    through the blade, constant theta downstream (the BladeGen convention of Rotor 37)."""
    camber = section.camber_line(CONTOUR_BLADE + 1)
    z_le, z_te = camber[0, 0], camber[-1, 0]
    th_le, th_te = camber[0, 1] / section.radius, camber[-1, 1] / section.radius
    z_up = np.linspace(Z_IN, z_le, CONTOUR_UP + 1)[:-1]
    z_down = np.linspace(z_te, Z_OUT, CONTOUR_DOWN + 1)[1:]
    z = np.concatenate([z_up, camber[:, 0], z_down])
    theta = np.concatenate([np.full(z_up.size, th_le), camber[:, 1] / section.radius,
                            np.full(z_down.size, th_te)])
    r = radius_function(z)
    # Through the blade the contour is the cylinder: use the section radius exactly.
    r[z_up.size:z_up.size + camber.shape[0]] = section.radius
    return np.stack([r * np.cos(theta), r * np.sin(theta), z], axis=-1)


def span_label(percent):
    if percent < 10:
        return "%.4f" % percent
    if percent < 100:
        return "%.2f" % percent
    return "%.1f" % percent


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    sections = [Section(s) for s in SPANS]

    assert abs(hub_radius(0.0) - sections[0].radius) < 1e-15
    assert abs(shroud_radius(0.0) - sections[-1].radius) < 1e-15

    with open(os.path.join(here, "BladeGen.inf"), "w", newline="\n") as f:
        f.write("!======  BlockForge generate_distributor.py (CFX-BladeGen layout)  ========\n"
                "Axis of Rotation: Z\n"
                "Number of Blade Sets: %d\n"
                "Geometry Units: %s\n"
                "Hub Data File: hub.curve\n"
                "Shroud Data File: shroud.curve\n"
                "Profile Data File: profile.curve\n" % (BLADE_COUNT, UNITS))

    for name, sec, fn in (("hub.curve", sections[0], hub_radius),
                          ("shroud.curve", sections[-1], shroud_radius)):
        with open(os.path.join(here, name), "w", newline="\n") as f:
            for p in contour(sec, fn):
                f.write(row(p) + "\n")

    with open(os.path.join(here, "profile.curve"), "w", newline="\n") as f:
        for k, sec in enumerate(sections, start=1):
            f.write("# Profile %d at %s%%\n" % (k, span_label(100.0 * sec.s)))
            for p in sec.wrap(sec.loop()):
                f.write(row(p) + "\n")
            f.write("\n")

    # Summary of the design (what README.md quotes).
    print("k  span%  r[m]   NACA(m,p,t)        chord  stagger  solidity  t/c    "
          "TE-radius  area[m2]   z_LE      z_TE      theta_LE  theta_TE  gap[m]")
    for k, sec in enumerate(sections, start=1):
        mu = sec.loop()
        area = 0.5 * np.sum(mu[:-1, 0] * mu[1:, 1] - mu[1:, 0] * mu[:-1, 1])
        pitch = 2 * math.pi * sec.radius / BLADE_COUNT
        # minimum distance to the periodic neighbour (shifted by one pitch in u)
        other = mu + np.array([0.0, pitch])
        gap = np.min(np.hypot(*(mu[:, None, :] - other[None, :, :]).transpose(2, 0, 1)))
        q = np.linspace(0.0, 2.0, 20001)
        thickness = np.max(np.hypot(*(sec.side_normalised(q, 1.0)
                                      - sec.side_normalised(q, -1.0)).T))
        tmax = thickness / sec.nominal_length  # max thickness / chord (perpendicular to camber)
        print("%d  %5.1f  %.3f  (%.4f,%.1f,%.4f)  %.3f  %6.2f   %.4f    %.4f  %.6f   %.7f  "
              "%+.6f  %+.6f  %+.6f  %+.6f  %.4f"
              % (k, 100 * sec.s, sec.radius, sec.m, sec.p, sec.t, sec.chord, sec.stagger,
                 sec.chord / pitch, tmax, sec.rho * sec.chord / sec.nominal_length, area,
                 mu[0, 0], mu[150, 0], mu[0, 1] / sec.radius, mu[150, 1] / sec.radius, gap))


if __name__ == "__main__":
    main()
