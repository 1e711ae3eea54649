"""A KiCad board written by kiutils for the import tests, with its known geometry.

KiCad coordinates are mm with y down; the board occupies x 50..150, y 30..110 with a 20 x 10 mm
notch cut from its top-right corner (on screen), a 10 x 6 mm rectangular cut-out and a 4 mm round
one. Stack-up (top to bottom): mask 0.01, copper 0.035, FR4 core 1.51, copper 0.035, mask 0.01.
"""

from kiutils.board import Board
from kiutils.footprint import DrillDefinition, Footprint, Pad
from kiutils.items.brditems import Stackup, StackupLayer
from kiutils.items.common import Position
from kiutils.items.fpitems import FpRect
from kiutils.items.gritems import GrCircle, GrLine, GrRect

X0, Y0, W, H = 50.0, 30.0, 100.0, 80.0
NOTCH = (20.0, 10.0)  # removed at the top-right corner as seen on screen (KiCad x max, y min)
CUT_RECT = ((70.0, 60.0), (80.0, 66.0))  # KiCad corners of the rectangular cut-out
CUT_CIRCLE = ((120.0, 90.0), 4.0)  # centre, diameter
LAYERS = [("F.Mask", "Top Solder Mask", 0.01, None), ("F.Cu", "copper", 0.035, None),
          ("dielectric 1", "core", 1.51, "FR4"), ("B.Cu", "copper", 0.035, None),
          ("B.Mask", "Bottom Solder Mask", 0.01, None)]
#: ref, footprint, KiCad position (x, y, angle), side, courtyard corners (local), pad (size, drill) or None
PARTS = [
    ("U1", "Package_QFP:LQFP-64_10x10mm_P0.5mm", (75.0, 45.0, 0.0), "F", ((-6.5, -6.5), (6.5, 6.5)), None),
    ("U2", "Package_SO:SOIC-8_3.9x4.9mm_P1.27mm", (110.0, 55.0, 30.0), "B", ((-2.0, -2.7), (5.4, 2.7)), None),
    ("C1", "Capacitor_THT:CP_Radial_D10.0mm_P5.00mm", (100.0, 85.0, 90.0), "F", ((-5.5, -5.2), (5.5, 6.8)), None),
    ("X1", "Connector_PinHeader_2.54mm:PinHeader_1x04_P2.54mm_Horizontal", (60.0, 100.0, 0.0), "F",
     ((-5.0, -2.0), (5.0, 14.0)), None),
    ("J1", "Connector_Weird:Thing", (130.0, 50.0, 0.0), "F", ((-2.0, -2.0), (2.0, 2.0)), None),
    ("J2", "Connector_Weird:Thing", (130.0, 70.0, 0.0), "F", ((-2.0, -2.0), (2.0, 2.0)), None),
    ("FID1", "Fiducial:Fiducial_1mm_Mask2mm", (90.0, 100.0, 0.0), "F", ((-1.0, -1.0), (1.0, 1.0)), None),
    ("H1", "MountingHole:MountingHole_3.2mm_M3_Pad", (55.0, 35.0, 0.0), "F", None, (6.4, 3.2)),
    ("H2", "MountingHole:MountingHole_3.2mm_M3_Pad", (145.0, 105.0, 0.0), "F", None, (6.4, 3.2)),
]
MAP = '''
[footprints]
"Package_QFP:LQFP-*" = "CQFP"
"Package_SO:SOIC-*" = { mass = "0.08 g" }
"Capacitor_THT:CP_Radial_*" = { mass = "2 g", height = "12 mm", model = "lumped" }
"Connector_PinHeader_2.54mm:*" = { mass = "1 g" }
"Fiducial:*" = "ignore"
'''


def _pos(x, y, angle=None):
    return Position(X=x, Y=y, angle=angle)


def outline_kicad():
    """The outline's corners in KiCad coordinates (clockwise on screen)."""
    nx, ny = NOTCH
    return [(X0, Y0), (X0 + W - nx, Y0), (X0 + W - nx, Y0 + ny), (X0 + W, Y0 + ny), (X0 + W, Y0 + H), (X0, Y0 + H)]


def write_board(path, parts=PARTS, circle=True) -> None:
    pcb = Board.create_new()
    pcb.general.thickness = sum(t for _, _, t, _ in LAYERS)
    pcb.setup.stackup = Stackup(layers=[StackupLayer(name="F.SilkS", type="Top Silk Screen")] + [
        StackupLayer(name=n, type=k, thickness=t, material=m) for n, k, t, m in LAYERS])
    pts = outline_kicad()
    for a, b in zip(pts, pts[1:] + pts[:1]):
        pcb.graphicItems.append(GrLine(start=_pos(*a), end=_pos(*b), layer="Edge.Cuts"))
    pcb.graphicItems.append(GrRect(start=_pos(*CUT_RECT[0]), end=_pos(*CUT_RECT[1]), layer="Edge.Cuts"))
    (cx, cy), d = CUT_CIRCLE
    if circle:
        pcb.graphicItems.append(GrCircle(center=_pos(cx, cy), end=_pos(cx + d / 2, cy), layer="Edge.Cuts"))
    for ref, lib, (x, y, ang), side, court, pad in parts:
        fp = Footprint()
        fp.libId = lib
        fp.layer = f"{side}.Cu"
        fp.position = _pos(x, y, ang)
        fp.properties = {"Reference": ref, "Value": lib.split(":")[1]}
        if court is not None:
            fp.graphicItems.append(FpRect(start=_pos(*court[0]), end=_pos(*court[1]), layer=f"{side}.CrtYd"))
        if pad is not None:
            size, drill = pad
            fp.pads.append(Pad(number="1", type="thru_hole", shape="circle", position=_pos(0.0, 0.0),
                               size=_pos(size, size), drill=DrillDefinition(diameter=drill),
                               layers=["*.Cu", "*.Mask"]))
        pcb.footprints.append(fp)
    pcb.to_file(str(path))
