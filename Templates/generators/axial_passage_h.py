#!/usr/bin/python3
"""Writes Templates/axial_passage_h.yaml.

The hub and shroud layers of the H-grid template are the same text but for their names
(_h on `hub`, _s on `shroud`), so they are written from one description here; edit this
file, then run it (CTest's Templates.axial_passage_h_generated checks that this script
and the template agree).

Usage: /usr/bin/python3 Templates/generators/axial_passage_h.py [--check]
  --check: exit 1 (and say so) when the template differs from what this script writes.
"""
import os
import sys

from template_file import write_or_check

TEMPLATE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "axial_passage_h.yaml")

HEADER = """# Written by Templates/generators/axial_passage_h.py: edit that, then run it.
# axial_passage_h: H-grid of one blade passage of an axial turbomachine (format 2), from
# hub, shroud and blade sections (TurboPointSetsReader output), after Kolsek et al. 2003.
# The same parameters mesh Data/rotor37/turbogrid (36 blades) and Data/distributor (16 vanes).
#
#   Unrolled at the hub (axial up, theta to the right); the same at the shroud (_s):
#
#        lo_out ------------ mo ------------ hi_out        outlet
#          |       DL        |       DR        |
#        lo_te ------------- te ------------ hi_te         trailing edge
#          |       AL      a(  )b     AR       |
#        lo_mid --------- a_mid  b_mid ----- hi_mid        mid-chord, both blade sides
#          |       BL      a(  )b     BR       |
#        lo_le ------------- le ------------ hi_le         leading edge
#          |       UL        |       UR        |
#        lo_in ------------- mi ------------ hi_in         inlet
#
#     periodic_low (lo_*)               periodic_high (hi_* = lo_* rotated by one pitch)
#
# The blade is a Gordon surface through the closed sections, extended to meet the hub and
# shroud surfaces of revolution; le/te are the smallest/largest axial positions on those
# intersection curves, a_mid/b_mid the mid-parameters of the two blade sides. The lo_*
# vertices are half a pitch from the blade (in theta), the hi_* their periodic images.
# Every block runs i with theta, j with the axis, k from hub to shroud.
#
# Nothing depends on how the export orders the sections: le/te are the extreme axial points
# of the blade-hub (blade-shroud) intersection curve, the blade side facing periodic_low
# (side a) is the one whose mid-parameter point has the smaller theta, and the inlet and
# outlet are axial planes upstream of the first leading edge and downstream of the last
# trailing edge (hub or shroud), at distances given in blade axial lengths. The same
# parameters mesh Data/rotor37/turbogrid (36 blades, leaning +theta) and Data/distributor
# (16 vanes, leaning -theta). theta is measured from the blade (machine: theta_zero).
# Where the hub and shroud contours end nearer the blade than asked (the inlet or outlet
# then sits where they end), the upstream and downstream blocks get fewer cells, 0.4 of the
# blade blocks' mean axial cell long, instead of n_up (n_down) cells squeezed into the gap.
blockforge: 2
name: axial_passage_h
description: H-grid of one blade passage from hub, shroud and blade sections.

inputs: {hub: Hub, shroud: Shroud, sections: Profiles}
machine: {theta_zero: sections}   # theta = 0 through the blade, so the passage is away from the seam theta = +-pi

parameters:
  upstream: 0.7           # inlet distance upstream of the first leading edge [blade axial lengths]
  downstream: 0.9         # outlet distance downstream of the last trailing edge [blade axial lengths]
  extend: 0               # extend hub and shroud along their end tangents by this fraction of their length (0: inlet/outlet stop at the contour ends when those are nearer)
  n_up: 8                 # cells from inlet to leading edge (fewer where the inlet is nearer than asked)
  n_chord: 10             # cells along each half chord
  n_down: 8               # cells from trailing edge to outlet (fewer where the outlet is nearer than asked)
  n_pitch: 8              # cells across each half pitch
  n_span: 12              # cells from hub to shroud
  span_wall: 0.5          # hub and shroud cells' height relative to the mean spanwise cell (law ends; 1: uniform): end-wall layers, and wall cells whose internal faces span three directions where a blade side meets the trailing-edge line at an acute angle (turbine)
  k_match: 1.2            # largest growth ratio of the cells along the axis and across the pitch, whose end cells match their neighbours' (law match)
  lean: 75deg             # blade sides: the first cell at a leading or trailing edge leans at most this much from the side's chord (a round edge is left across the pitch: its cell is lengthened, and the cells continuing it too)

definitions:
  blade_axial: "max(te_h.axial, te_s.axial) - min(le_h.axial, le_s.axial)"   # axial extent of the blade
  inlet_wanted: "min(le_h.axial, le_s.axial) - upstream*blade_axial"
  outlet_wanted: "max(te_h.axial, te_s.axial) + downstream*blade_axial"
  # inlet and outlet planes: where asked, or where the hub and shroud contours start and
  # end when they are nearer (a hair inside, so that both surfaces reach the plane)
  inlet_axial: "max(inlet_wanted, max(hub.axial_min, shroud.axial_min) + 1e-9*blade_axial)"
  outlet_axial: "min(outlet_wanted, min(hub.axial_max, shroud.axial_max) - 1e-9*blade_axial)"
  # cells upstream and downstream: n_up (n_down), but no more than cells of 0.4 times the
  # blade blocks' mean axial cell (blade_axial/(2 n_chord)) fill the gap: where the
  # contours end close to the blade, n_up cells there were thin slabs (aspect ratio up to
  # 60, failing checkMesh's determinant check); much larger cells there coarsen the
  # edges' first cells through the match law (passage volume off by 0.6 % at density 0.5)
  cells_up: "min(n_up, max(1, rint((min(le_h.axial, le_s.axial) - inlet_axial)/(blade_axial/(5*n_chord)))))"
  cells_down: "min(n_down, max(1, rint((outlet_axial - max(te_h.axial, te_s.axial))/(blade_axial/(5*n_chord)))))"

carriers:
  hub: {revolve: hub, axis: machine, extend: extend}
  shroud: {revolve: shroud, axis: machine, extend: extend}
  blade: {gordon: sections, blending: spline, closed: true, align: axial}   # every section: leading edge at s = 0.25, trailing edge at 0.75 (the spanwise edges follow the thin edges)
  blade_h: {intersect: [blade, hub]}
  blade_s: {intersect: [blade, shroud]}
"""

FOOTER = """blocks:
  UL: {vertices: [lo_in_h, mi_h, le_h, lo_le_h, lo_in_s, mi_s, le_s, lo_le_s], cells: [n_pitch, cells_up, n_span], grading: {i: {match: k_match}, j: {match: k_match}, k: {ends: [span_wall, span_wall]}}}
  UR: {vertices: [mi_h, hi_in_h, hi_le_h, le_h, mi_s, hi_in_s, hi_le_s, le_s], cells: [n_pitch, cells_up, n_span], grading: {i: {match: k_match}, j: {match: k_match}, k: {ends: [span_wall, span_wall]}}}
  BL: {vertices: [lo_le_h, le_h, a_mid_h, lo_mid_h, lo_le_s, le_s, a_mid_s, lo_mid_s], cells: [n_pitch, n_chord, n_span], grading: {i: {match: k_match}, j: {match: k_match, lean: lean}, k: {ends: [span_wall, span_wall]}}}
  BR: {vertices: [le_h, hi_le_h, hi_mid_h, b_mid_h, le_s, hi_le_s, hi_mid_s, b_mid_s], cells: [n_pitch, n_chord, n_span], grading: {i: {match: k_match}, j: {match: k_match, lean: lean}, k: {ends: [span_wall, span_wall]}}}
  AL: {vertices: [lo_mid_h, a_mid_h, te_h, lo_te_h, lo_mid_s, a_mid_s, te_s, lo_te_s], cells: [n_pitch, n_chord, n_span], grading: {i: {match: k_match}, j: {match: k_match, lean: lean}, k: {ends: [span_wall, span_wall]}}}
  AR: {vertices: [b_mid_h, hi_mid_h, hi_te_h, te_h, b_mid_s, hi_mid_s, hi_te_s, te_s], cells: [n_pitch, n_chord, n_span], grading: {i: {match: k_match}, j: {match: k_match, lean: lean}, k: {ends: [span_wall, span_wall]}}}
  DL: {vertices: [lo_te_h, te_h, mo_h, lo_out_h, lo_te_s, te_s, mo_s, lo_out_s], cells: [n_pitch, cells_down, n_span], grading: {i: {match: k_match}, j: {match: k_match}, k: {ends: [span_wall, span_wall]}}}
  DR: {vertices: [te_h, hi_te_h, hi_out_h, mo_h, te_s, hi_te_s, hi_out_s, mo_s], cells: [n_pitch, cells_down, n_span], grading: {i: {match: k_match}, j: {match: k_match}, k: {ends: [span_wall, span_wall]}}}

faces:
  hub_faces: {on_surface: hub, faces: [UL.k0, UR.k0, BL.k0, BR.k0, AL.k0, AR.k0, DL.k0, DR.k0]}
  shroud_faces: {on_surface: shroud, faces: [UL.k1, UR.k1, BL.k1, BR.k1, AL.k1, AR.k1, DL.k1, DR.k1]}
  blade_faces: {on_surface: blade, faces: [BL.i1, AL.i1, BR.i0, AR.i0]}

patches:
  hub: {type: wall, faces: [UL.k0, UR.k0, BL.k0, BR.k0, AL.k0, AR.k0, DL.k0, DR.k0]}
  shroud: {type: wall, faces: [UL.k1, UR.k1, BL.k1, BR.k1, AL.k1, AR.k1, DL.k1, DR.k1]}
  blade: {type: wall, faces: [BL.i1, AL.i1, BR.i0, AR.i0]}
  inlet: {type: inlet, faces: [UL.j0, UR.j0]}
  outlet: {type: outlet, faces: [DL.j1, DR.j1]}
  periodic_low: {type: periodic, faces: [UL.i0, BL.i0, AL.i0, DL.i0], partner: periodic_high, pitches: 1}
  periodic_high: {type: periodic, faces: [UR.i1, BR.i1, AR.i1, DR.i1]}

notes:
  inlet: {when: "inlet_axial > inlet_wanted", say: "the inlet is where the hub and shroud contours start, {(min(le_h.axial, le_s.axial) - inlet_axial)/blade_axial} blade axial lengths upstream of the leading edge instead of {upstream} (set extend to continue the contours along their end tangents)"}
  outlet: {when: "outlet_axial < outlet_wanted", say: "the outlet is where the hub and shroud contours end, {(outlet_axial - max(te_h.axial, te_s.axial))/blade_axial} blade axial lengths downstream of the trailing edge instead of {downstream} (set extend to continue the contours along their end tangents)"}
"""


def side_parameters(l):
    """Curve parameters on blade_<l> (written out in full, for the template's expressions):
    fwd, the parameter distance from le to te in increasing s; the mid-point and the end (te)
    of side a (towards periodic_low) and of side b. dir (+1 when side a lies in increasing s
    from le) is found from the mid-points fm and bm of the two arcs."""
    fwd = f'(te_{l}.s < le_{l}.s ? te_{l}.s - le_{l}.s + 1 : te_{l}.s - le_{l}.s)'
    d = f'(sin(fm_{l}.theta - bm_{l}.theta) < 0 ? 1 : -1)'
    side_a = f'({d} > 0 ? {fwd} : 1 - {fwd})'
    return (fwd, f'le_{l}.s + {d}*{side_a}/2', f'le_{l}.s + {d}*{side_a}',
            f'le_{l}.s - {d}*(1 - {side_a})/2', f'le_{l}.s - {d}*(1 - {side_a})')


def template_text():
    out = [HEADER]
    w = out.append
    layers = {'h': 'hub', 's': 'shroud'}
    w('vertices:')
    for l, S in layers.items():
        fwd, a_mid, _, b_mid, _ = side_parameters(l)
        w(f'  # --- {S}: fm/bm are the mid-points of the two arcs le -> te (forward and backward in s)')
        w(f'  le_{l}:     {{on_curve: blade_{l}, at: {{min: axial}}}}')
        w(f'  te_{l}:     {{on_curve: blade_{l}, at: {{max: axial}}}}')
        w(f'  fm_{l}:     {{on_curve: blade_{l}, at: "le_{l}.s + {fwd}/2"}}')
        w(f'  bm_{l}:     {{on_curve: blade_{l}, at: "le_{l}.s + {fwd}/2 + 0.5"}}')
        w(f'  a_mid_{l}:  {{on_curve: blade_{l}, at: "{a_mid}"}}')
        w(f'  b_mid_{l}:  {{on_curve: blade_{l}, at: "{b_mid}"}}')
        w(f'  lo_le_{l}:  {{project: {{cylindrical: [le_{l}.axial, le_{l}.radius, le_{l}.theta - pitch/2]}}, onto: {S}}}')
        w(f'  lo_mid_{l}: {{project: {{cylindrical: ["(a_mid_{l}.axial + b_mid_{l}.axial)/2", a_mid_{l}.radius, "(a_mid_{l}.theta + b_mid_{l}.theta)/2 - pitch/2"]}}, onto: {S}}}')
        w(f'  lo_te_{l}:  {{project: {{cylindrical: [te_{l}.axial, te_{l}.radius, te_{l}.theta - pitch/2]}}, onto: {S}}}')
        w(f'  lo_in_{l}: {{on_surface: {S}, axial: inlet_axial, theta: "le_{l}.theta - pitch/2"}}')
        w(f'  mi_{l}: {{on_surface: {S}, axial: inlet_axial, theta: le_{l}.theta}}')
        w(f'  lo_out_{l}: {{on_surface: {S}, axial: outlet_axial, theta: "te_{l}.theta - pitch/2"}}')
        w(f'  mo_{l}: {{on_surface: {S}, axial: outlet_axial, theta: te_{l}.theta}}')
        for v in ('in', 'le', 'mid', 'te', 'out'):
            w(f'  hi_{v}_{l}:{" " * (4 - len(v))}{{periodic: lo_{v}_{l}}}')
    w('')
    w('edges:')
    for l, S in layers.items():
        _, a_mid, a_end, b_mid, b_end = side_parameters(l)
        w(f'  # --- on the {S}: blade sides (side a from le in the direction of a_mid), then lines straight in (s, t)')
        w(f'  le_a_{l}:  {{on_curve: blade_{l}, between: [le_{l}, a_mid_{l}], at: [le_{l}.s, "{a_mid}"]}}')
        w(f'  a_te_{l}:  {{on_curve: blade_{l}, between: [a_mid_{l}, te_{l}], at: ["{a_mid}", "{a_end}"]}}')
        w(f'  le_b_{l}:  {{on_curve: blade_{l}, between: [le_{l}, b_mid_{l}], at: [le_{l}.s, "{b_mid}"]}}')
        w(f'  b_te_{l}:  {{on_curve: blade_{l}, between: [b_mid_{l}, te_{l}], at: ["{b_mid}", "{b_end}"]}}')
        for a, b in (('lo_in', 'mi'), ('mi', 'hi_in'), ('lo_le', 'le'), ('le', 'hi_le'), ('lo_mid', 'a_mid'),
                     ('b_mid', 'hi_mid'), ('lo_te', 'te'), ('te', 'hi_te'), ('lo_out', 'mo'), ('mo', 'hi_out'),
                     ('lo_in', 'lo_le'), ('lo_le', 'lo_mid'), ('lo_mid', 'lo_te'), ('lo_te', 'lo_out'),
                     ('mi', 'le'), ('te', 'mo')):
            w(f'  {a}_{b}_{l}: {{on_surface: {S}, between: [{a}_{l}, {b}_{l}]}}')
    w('  # --- spanwise on the blade')
    for v in ('le', 'te', 'a_mid', 'b_mid'):
        w(f'  {v}_span:{" " * (6 - len(v))}{{on_surface: blade, between: [{v}_h, {v}_s]}}')
    w('')
    w(FOOTER)
    return "\n".join(out)


def main(argv):
    return write_or_check(TEMPLATE, template_text(), __file__, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
