#!/usr/bin/python3
"""Two more blade rows for BlockForge's tests, each written the way another design tool
exports it, and each chosen to stress the reader and the passage templates:

- turbine/    a high-turning turbine rotor row (turning 110 deg at the hub, 88 at the tip),
              thick rounded leading edge, blunt trailing edge left OPEN in the file (gap
              1.5 % of the chord), hub and shroud contours ending 10 % of a chord before
              the leading edge and after the trailing edge. Export style: an Info.txt
              (axis X, unit mm) beside hub_turbine.dat, shroud_turbine.dat and
              profile_turbine.dat; CRLF line ends, tab-separated columns; the sections are
              headed "## HP rotor" once, then "# Rotor1 Profile k" (no span: the reader
              spreads them evenly, which is where they are), each followed by a comment
              line "# pressure side from TE, suction side to TE".
- compressor/ a transonic-style compressor rotor: sharp leading and trailing edges
              (double-circular-arc thickness, wedge angles 4-9 deg), high stagger (30 deg at
              the hub, 60 deg at the tip), thin sections (t/c 7 % to 3 %), 25 sections,
              a hub rising 9 deg through the row. Export style: a BladeGen-like
              rotor.inf (lower-case keys, axis Y, unit inch) naming comma-separated .csv
              files with a "x,y,z" column row; sections headed "# Profile k at s%" with
              spans such as 4.16667 %, not repeating their first point: the last point is
              the trailing edge reached from the other side, 0.02 % of the chord away
              (rounding in the design tool).

Run:  /usr/bin/python3 generate_blade_rows.py    (numpy only; deterministic; overwrites the
      files of both folders and nothing else)

Both blades are built the same way, in the unrolled plane (m, u) = (axial, r theta) of the
cylinder of each section: a camber line whose angle from the axis varies linearly with its
arc length (a circular arc) from the inlet to the outlet metal angle, a thickness t(s)
normal to it (s = 0 at the leading edge, 1 at the trailing edge, points clustered at both
edges by cosine spacing), the chord scaled to c and the chord mid-point stacked at m = 0,
u = 0; then wrapped onto the cylinder (an isometry). What the tests may rely on is listed in
each folder's README.md.
"""

import math
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

TURBINE = dict(
    folder="turbine",
    blades=60,
    unit="MM",                  # lengths below in mm
    radii=np.linspace(249.0, 296.0, 9),       # sections from 1 mm inside the hub to ~2 mm past the shroud
    chord=lambda s: 30.0 + 4.0 * s,           # [mm]
    beta_in=lambda s: 40.0 - 6.0 * s,         # inlet metal angle from the axis [deg]
    beta_out=lambda s: -70.0 + 2.0 * s,       # outlet metal angle [deg]: turning 110 .. 86
    t_max=0.22,                               # max thickness / chord (NACA law, round LE)
    t_te=0.015,                               # trailing-edge thickness / chord: left open
    points_per_side=80,
    hub=lambda x: 250.0 - 0.05 * x,           # r(x) [mm]
    shroud=lambda x: 292.0 + 0.15 * x,
    contour_margin=0.10,                      # contours end this many chords from the blade
    contour_points=41,
)

COMPRESSOR = dict(
    folder="compressor",
    blades=30,
    unit="IN",
    radii=np.linspace(6.4, 10.1, 25),         # 25 sections, the first inside the hub, the last past the shroud
    chord=lambda s: 2.4 + 0.2 * s,            # [in]
    beta_in=lambda s: 45.0 + 18.0 * s,        # [deg]
    beta_out=lambda s: 15.0 + 42.0 * s,       # turning 30 deg at the hub .. 3 deg at the tip
    t_max_of=lambda s: 0.07 - 0.04 * s,       # double circular arc: sharp edges
    points_per_side=60,
    rounding_gap=2e-4,                        # last point: the TE from the other side, this far off
    hub=lambda x: 6.9 + 0.16 * x,
    shroud=lambda x: 10.0 - 0.04 * x,
    contour_margin=1.5,
    contour_points=61,
)


def camber_line(chord, beta_in, beta_out, s):
    """Points (m, u) and unit normals of a circular-arc camber line of chord `chord` at
    parameters s in [0, 1] (arc length fraction), chord mid-point at the origin."""
    b1, b2 = math.radians(beta_in), math.radians(beta_out)
    fine = np.linspace(0.0, 1.0, 4001)
    angle = b1 + (b2 - b1) * fine
    step = np.diff(fine)
    mid = 0.5 * (angle[1:] + angle[:-1])
    m = np.concatenate([[0.0], np.cumsum(np.cos(mid) * step)])
    u = np.concatenate([[0.0], np.cumsum(np.sin(mid) * step)])
    scale = chord / math.hypot(m[-1], u[-1])
    m, u = m * scale, u * scale
    m -= 0.5 * m[-1]
    u -= 0.5 * u[-1]
    a = b1 + (b2 - b1) * s
    points = np.stack([np.interp(s, fine, m), np.interp(s, fine, u)], axis=-1)
    normals = np.stack([-np.sin(a), np.cos(a)], axis=-1)
    return points, normals


def turbine_thickness(s, t_max, t_te):
    """NACA 4-digit law with a closed end (round leading edge, radius 1.1 t^2) plus a
    linear part that leaves the trailing edge t_te thick."""
    naca = 5.0 * t_max * (0.2969 * np.sqrt(s) - 0.1260 * s - 0.3516 * s**2
                          + 0.2843 * s**3 - 0.1036 * s**4)
    return 2.0 * naca + t_te * s


def compressor_thickness(s, t_max):
    """Double circular arc (parabolic here): sharp edges, wedge angle about 4 t_max rad."""
    return 4.0 * t_max * s * (1.0 - s)


def wrap(mu, radius, axis):
    """(m, u) on the cylinder of `radius` -> x, y, z for the machine axis "X" or "Y"."""
    theta = mu[:, 1] / radius
    m = mu[:, 0]
    if axis == "X":   # X x Y = Z: theta from +Y towards +Z
        return np.stack([m, radius * np.cos(theta), radius * np.sin(theta)], axis=-1)
    # Y x Z = X: theta from +Z towards +X
    return np.stack([radius * np.sin(theta), m, radius * np.cos(theta)], axis=-1)


def meridional(x, r, axis):
    zero = np.zeros_like(x)
    if axis == "X":
        return np.stack([x, r, zero], axis=-1)
    return np.stack([zero, x, r], axis=-1)


def sections(design, thickness):
    """The (m, u) loops of every section: list of (radius, span fraction, points)."""
    result = []
    radii = design["radii"]
    n = design["points_per_side"]
    s = 0.5 * (1.0 - np.cos(np.linspace(0.0, math.pi, n)))  # LE -> TE, clustered at both
    for radius in radii:
        f = (radius - radii[0]) / (radii[-1] - radii[0])
        chord = design["chord"](f)
        centre, normal = camber_line(chord, design["beta_in"](f), design["beta_out"](f), s)
        half = 0.5 * chord * thickness(s, f)[:, None]
        upper = centre + half * normal
        lower = centre - half * normal
        result.append((radius, f, chord, upper, lower))
    return result


def write_turbine(design):
    folder = os.path.join(HERE, design["folder"])
    os.makedirs(folder, exist_ok=True)
    rows = sections(design, lambda s, f: turbine_thickness(s, design["t_max"], design["t_te"]))
    lines = ["## HP rotor"]
    ends = []
    for k, (radius, f, chord, upper, lower) in enumerate(rows, start=1):
        # From the trailing-edge end of the lower side round the leading edge to the
        # trailing-edge end of the upper side: the blunt edge stays open.
        loop = np.concatenate([lower[::-1], upper[1:]])
        xyz = wrap(loop, radius, "X")
        lines.append("# Rotor1 Profile %d" % k)
        lines.append("# pressure side from TE, suction side to TE")
        lines += ["%.6f\t%.6f\t%.6f" % tuple(p) for p in xyz]
        ends.append((loop[:, 0].min(), loop[:, 0].max(), chord))
    with open(os.path.join(folder, "profile_turbine.dat"), "w", newline="\r\n") as f:
        f.write("\n".join(lines) + "\n")
    x_le = min(e[0] for e in ends)
    x_te = max(e[1] for e in ends)
    margin = design["contour_margin"] * rows[0][2]
    x = np.linspace(x_le - margin, x_te + margin, design["contour_points"])
    for name, radius in (("hub", design["hub"]), ("shroud", design["shroud"])):
        with open(os.path.join(folder, name + "_turbine.dat"), "w", newline="\r\n") as f:
            for p in meridional(x, radius(x), "X"):
                f.write("%.6f\t%.6f\t%.6f\n" % tuple(p))
    with open(os.path.join(folder, "Info.txt"), "w", newline="\r\n") as f:
        f.write("No of blades : %d\nAxis of rotation : X\nCoordinates unit : mm\n"
                "Machine type : Axial turbine rotor (synthetic, BlockForge)\n"
                % design["blades"])
    return rows, x


def write_compressor(design):
    folder = os.path.join(HERE, design["folder"])
    os.makedirs(folder, exist_ok=True)
    rows = sections(design, lambda s, f: compressor_thickness(s, design["t_max_of"](f)))
    count = len(rows)
    lines = ["x,y,z", "## R1 transonic rotor"]
    extent = []
    for k, (radius, f, chord, upper, lower) in enumerate(rows, start=1):
        # From the trailing edge along the upper side, round the sharp leading edge, back
        # along the lower side; the last point is the trailing edge reached from the lower
        # side, `rounding_gap` chords off the first (the design tool's rounding).
        loop = np.concatenate([upper[::-1], lower[1:]])
        loop[-1] = loop[0] + design["rounding_gap"] * chord * np.array([0.6, -0.8])
        xyz = wrap(loop, radius, "Y")
        lines.append("# Profile %d at %.6g%%" % (k, 100.0 * (k - 1) / (count - 1)))
        lines += ["%.7f,%.7f,%.7f" % tuple(p) for p in xyz]
        extent.append((loop[:, 0].min(), loop[:, 0].max(), chord))
    with open(os.path.join(folder, "profile.csv"), "w", newline="\n") as f:
        f.write("\n".join(lines) + "\n")
    x_le = min(e[0] for e in extent)
    x_te = max(e[1] for e in extent)
    margin = design["contour_margin"] * rows[0][2]
    x = np.linspace(x_le - margin, x_te + margin, design["contour_points"])
    for name, radius in (("hub", design["hub"]), ("casing", design["shroud"])):
        with open(os.path.join(folder, name + ".csv"), "w", newline="\n") as f:
            f.write("x,y,z\n")
            for p in meridional(x, radius(x), "Y"):
                f.write("%.7f,%.7f,%.7f\n" % tuple(p))
    with open(os.path.join(folder, "rotor.inf"), "w", newline="\n") as f:
        f.write("! R1 transonic rotor, exported for meshing (synthetic, BlockForge)\n"
                "axis of rotation: Y\n"
                "number of blade sets: %d\n"
                "geometry units: inch\n"
                "hub data file: hub.csv\n"
                "shroud data file: casing.csv\n"
                "profile data file: profile.csv\n" % design["blades"])
    return rows, x


def summary(name, design, rows, x):
    print("%s: %d blades, %d sections, unit %s, contours x = %.4f .. %.4f"
          % (name, design["blades"], len(rows), design["unit"], x[0], x[-1]))
    print("  k   r        span   chord   turning  stagger  t/c    solidity  m_LE     m_TE")
    for k, (radius, f, chord, upper, lower) in enumerate(rows, start=1):
        b1, b2 = design["beta_in"](f), design["beta_out"](f)
        ends = np.concatenate([upper, lower])
        width = np.max(np.linalg.norm(upper - lower, axis=1)) / chord
        stagger = math.degrees(math.atan2(upper[-1, 1] - upper[0, 1], upper[-1, 0] - upper[0, 0]))
        print("  %-3d %-8.4g %-6.3f %-7.4g %-8.1f %-8.1f %-6.3f %-9.3f %-8.4f %-8.4f"
              % (k, radius, f, chord, abs(b1 - b2), stagger, width,
                 chord * design["blades"] / (2 * math.pi * radius), ends[:, 0].min(),
                 ends[:, 0].max()))


def main():
    rows, x = write_turbine(TURBINE)
    summary("turbine", TURBINE, rows, x)
    rows, x = write_compressor(COMPRESSOR)
    summary("compressor", COMPRESSOR, rows, x)


if __name__ == "__main__":
    main()
