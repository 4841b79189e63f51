"""Plans wire-arc additive manufacturing (WAAM) of metal tubes on industrial
robots: non-planar constant-distance layers, tool axes, layer-by-layer joint
optimisation, FANUC/KUKA/ABB programs.

Units: mm, degrees (joints, R_Z), mm/s. Part-frame geometry; joints in the
robot controller's convention. Per-point data are read-only numpy arrays.
Slicing, planning, writing and checking release the GIL.
"""

import os
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

_PathLike = Union[str, "os.PathLike[str]"]

__version__: str

class WaamError(Exception):
    """Any error of the library; the message names the file, field,
    keyword, layer or point. Raised as one of its subclasses, by kind."""

class InputError(WaamError, ValueError):
    """Bad input: a part or cell file's field, a keyword, a program file."""

class InfeasiblePlan(WaamError):
    """A program was asked of a plan with an infeasible layer (an answer
    about the part in the cell, not bad input)."""

class Cancelled(WaamError):
    """The host stopped the run (cancel flag or progress callback)."""

class WaamIOError(WaamError, OSError):
    """A file could not be read or written (missing, permissions, disk)."""

class Part:
    """A tube to build: geometry, substrate and the part file's slicing,
    tool-axis and process settings. Part frame, mm."""

    @staticmethod
    def read(path: _PathLike) -> "Part":
        """Reads and validates a part file (TOML, see parts/README.md).
        Raises WaamError naming the file and the field."""
    @staticmethod
    def from_toml(text: str, name: str = "<string>") -> "Part":
        """Parses part-file text; `name` stands for the file in messages and
        relative paths in the text (an STL substrate) are resolved from its
        folder."""
    @staticmethod
    def from_mesh(
        path: _PathLike,
        *,
        start: Union[str, Tuple[float, float, float], None] = None,
        max_rms_mm: Optional[float] = None,
        template: Optional[_PathLike] = None,
        name: Optional[str] = None,
        station_spacing_mm: Optional[float] = None,
        knot_spacing_mm: Optional[float] = None,
        check_surface: Optional[bool] = None,
    ) -> "Part":
        """Fits a part to a tubular mesh (binary or ASCII STL, mm): a spline
        guide and a radius law from end to end (and the wall thickness when
        the mesh holds both skins), a flat substrate at the start end
        ("lowest", "highest", "capped" or nearest a point). Raises
        InputError naming the file and station for a mesh that is not one
        tube (a branch, a closed blob, a section far from a circle, a residual
        over max_rms_mm)."""
    @property
    def fit_report(self) -> Optional[Dict[str, Any]]:
        """The fit report (fit.json of `waam fit`: rms_mm, max_mm, stations,
        wall), or None for a part read from a file."""
    def write_fit(self, out: _PathLike) -> List[Path]:
        """Writes part.toml and fit.json of a fitted part into `out`."""
    @property
    def name(self) -> str:
        """The part's name (the file's `name`)."""
    @property
    def file(self) -> str:
        """The file it was read from, as given."""
    def slice(
        self,
        *,
        strategy: Optional[str] = None,
        delta_mm: Optional[float] = None,
        points: Optional[int] = None,
        chord_mm: Optional[float] = None,
        max_layers: Optional[int] = None,
        travel_speed_mm_s: Optional[float] = None,
        progress: Optional[Callable[[float], Any]] = None,
    ) -> "SlicedPart":
        """Slices the part with its file's settings; each keyword given
        overrides one of them.

        strategy: "constant", "iso", "perpendicular", "planar" or "spiral".
        delta_mm: target interlayer distance Delta (mm).
        points / chord_mm: points per layer, or max chord error (mm); one of them.
        max_layers: stop after this many layers (or spiral turns).
        travel_speed_mm_s: programmed torch speed (mm/s).
        progress: called with the fraction of the run done (0..1); an
            exception it raises stops the run and is re-raised.
        """
    def replan(
        self,
        cell: "Cell",
        measured: Union[_PathLike, npt.ArrayLike],
        *,
        after_layer: int,
        delta_mm: Optional[float] = None,
        points: Optional[int] = None,
        chord_mm: Optional[float] = None,
        rz: Optional[str] = None,
        max_layers: Optional[int] = None,
    ) -> "PlannedPart":
        """Replans the layers after `after_layer` from the measured top of that
        layer (a scan CSV `x,y,z` / `layer,point,dh_mm`, or an (N, 3) array of
        points, part frame, mm): corrected travel speeds, geometry where the
        speed window cannot absorb the error, joints optimised in `cell`.
        Returns the plan of the remaining layers; `summary()["replan"]` has the
        outliers and per layer the predicted error before and after. A scan of
        another layer or part raises InputError naming the distance."""
    def plan(
        self,
        cell: "Cell",
        *,
        delta_mm: Optional[float] = None,
        points: Optional[int] = None,
        chord_mm: Optional[float] = None,
        strategy: Optional[str] = None,
        rz: Optional[str] = None,
        travel_speed_mm_s: Optional[float] = None,
        max_layers: Optional[int] = None,
        progress: Optional[Callable[[float], Any]] = None,
        positioner: Optional[str] = None,
        format: Optional[str] = None,
    ) -> "PlannedPart":
        """Plans the part in `cell`: slice, tool axes, layer-by-layer R_Z
        optimisation, joint trajectory, program model. An infeasible layer
        is data (`feasible`, `violations`), not an exception.

        rz: the R_Z law, "fixed:DEG", "poly:N" (N <= 8, default "poly:4"),
            "spline" or "point". positioner (torch-carried cells):
            "optimised" (default: tilt and turn laws within the cell's cone
            of the vertical) or "vertical" (the build direction exactly
            vertical, as in the thesis). format: "fanuc", "kuka", "abb" or
            None (the cell robot's vendor's; another vendor's raises
            InputError before any work). Other keywords as in `slice`.
            Progress is reported at stage boundaries (slicing, optimising,
            program).
        """
    def place(
        self,
        cell: "Cell",
        *,
        delta_mm: Optional[float] = None,
        points: Optional[int] = None,
        chord_mm: Optional[float] = None,
        travel_speed_mm_s: Optional[float] = None,
        samples: Optional[int] = None,
        half_box_mm: Optional[float] = None,
    ) -> "PlacedCell":
        """Searches where the part should sit in `cell` (as `waam place`):
        the deposition point and the part's mount when the arm carries the
        part, the positioner's pose and the part's offset on the table
        (within 150 mm of the turn axis unless [placement] says otherwise)
        when it carries the torch; the fixture tilt, other part offsets and
        rotations and the torch clamp rotation when the cell file's
        [placement] table gives their ranges; so that every layer is
        feasible and the program stage accepts the plan, with the widest
        worst-layer margins. The cell as given is kept when it is as good.

        samples: candidates of the global screening (default 64).
        half_box_mm: half-width (mm) of the box searched around the cell's
            placement when its file has no [placement] bounds (default 400).
        A part no placement makes feasible gives a PlacedCell whose
        `feasible` is False and whose `binding` says why; bad bounds raise
        WaamError naming the field.
        """

class Cell:
    """A robot cell: the robot and its layout (part carried under a fixed
    torch, or torch carried over a positioner). Robot base frame, mm."""

    @staticmethod
    def read(path: _PathLike) -> "Cell":
        """Reads and validates a cell file (TOML, parts/cells/). A file
        describing a robot only is refused."""
    @staticmethod
    def from_toml(text: str, name: str = "<string>") -> "Cell":
        """Parses cell-file text; `name` stands for the file in messages."""
    @property
    def name(self) -> str:
        """The cell's name (the file's `name`)."""
    @property
    def file(self) -> str:
        """The file it was read from, as given."""
    @property
    def vendor(self) -> str:
        """The controller's program format: "fanuc", "kuka" or "abb"."""
    @property
    def has_positioner(self) -> bool:
        """True when the torch is carried over a positioner (joints have 8
        columns)."""

class SlicedPart:
    """A sliced part: every point of the path in deposition order."""

    @property
    def points(self) -> npt.NDArray[np.float64]:
        """Positions (N, 3), part frame, mm."""
    @property
    def layer(self) -> npt.NDArray[np.int64]:
        """Layer index of each point (N,), from 0."""
    @property
    def delta(self) -> npt.NDArray[np.float64]:
        """Local distance to the layer below (N,), mm; NaN on the first layer."""
    @property
    def tool_axis(self) -> npt.NDArray[np.float64]:
        """Tool axis of each point (N, 3), unit vectors, part frame."""
    @property
    def delta_mm(self) -> float:
        """The target interlayer distance Delta used (mm)."""
    @property
    def strategy(self) -> str:
        """The strategy used."""
    @property
    def layers(self) -> int:
        """Number of layers."""
    def summary(self) -> Dict[str, Any]:
        """The content of summary.json as `waam slice` writes it."""
    def __len__(self) -> int:
        """Number of points."""

class PlannedPart:
    """A part planned in a cell: every planned point in deposition order."""

    @property
    def feasible(self) -> bool:
        """True when every layer is feasible and a program can be written."""
    @property
    def violations(self) -> List[Dict[str, Any]]:
        """Every violation of the planned trajectory, in path order: dicts
        with `layer`, `point` (index in the layer), `joint` (1-based, 7/8 for
        the positioner, or None), `what` ("joint_limit", "joint_speed",
        "wrist_singularity", "elbow_singularity", "shoulder_singularity",
        "hose_torsion", "no_solution"), `amount` (how far past the limit; the
        measure itself for a singularity; None without solution), `unit` and
        `message`."""
    @property
    def refusal(self) -> Optional[str]:
        """Why no program can be written; None when feasible."""
    @property
    def points(self) -> npt.NDArray[np.float64]:
        """Positions of the planned points (N, 3), part frame, mm."""
    @property
    def tool_axis(self) -> npt.NDArray[np.float64]:
        """Tool axes (N, 3), unit vectors, part frame."""
    @property
    def layer(self) -> npt.NDArray[np.int64]:
        """Layer index of each point (N,)."""
    @property
    def rz_deg(self) -> npt.NDArray[np.float64]:
        """R_Z of each point (N,), degrees."""
    @property
    def joints(self) -> npt.NDArray[np.float64]:
        """Joints (N, 6), degrees, controller convention; (N, 8) with a
        positioner (its two joints last); NaN where a point has no solution."""
    @property
    def travel_speed_mm_s(self) -> float:
        """The process's travel speed (mm/s): every point's, but where the
        plan slowed the torch down (point_speed_mm_s)."""
    @property
    def point_speed_mm_s(self) -> npt.NDArray[np.float64]:
        """Travel speed on the way to each point (N,), mm/s: the process's,
        or slower where an axis could not keep up (the summary's slowed)."""
    @property
    def wire_feed_mm_s(self) -> npt.NDArray[np.float64]:
        """Wire feed on the way to each point (N,), mm/s: the process's,
        scaled with the speed where the torch slows (WFS/TS stays)."""
    @property
    def format(self) -> str:
        """The program format written by default (the cell vendor's)."""
    def summary(self) -> Dict[str, Any]:
        """The content of summary.json as `waam plan` writes it."""
    def write_program(self, dir: _PathLike) -> List[Path]:
        """Writes the robot program into `dir` (created if missing), each
        file atomically, in the plan's format (`Part.plan(format=...)`);
        returns the written paths in the order the cell runs them. Raises
        InfeasiblePlan when a layer is infeasible, WaamIOError when a file
        cannot be written."""
    def __len__(self) -> int:
        """Number of planned points."""

class PlacedCell:
    """A part placed in a cell by `Part.place`, or the search's account of
    why it cannot be."""

    @property
    def feasible(self) -> bool:
        """True when a placement makes every layer feasible and the program
        stage accepts the plan."""
    @property
    def cell(self) -> Cell:
        """The placed cell (the best candidate when none was found); pass it
        to `Part.plan`."""
    @property
    def toml(self) -> str:
        """The placed cell as a complete cell file (TOML), the margins
        achieved in its header comment; `waam plan` takes it unchanged."""
    @property
    def binding(self) -> Optional[str]:
        """The constraint that bound every candidate when none was found
        (with its share), None when found."""
    @property
    def values(self) -> Dict[str, float]:
        """Placement variable name -> value found (mm or degrees, the unit
        in summary()["variables"])."""
    def summary(self) -> Dict[str, Any]:
        """The content of placement.json as `waam place` writes it."""
    def write(self, dir: _PathLike) -> List[Path]:
        """Writes placement.json and, when a placement was found, cell.toml
        into `dir` (created if missing), each atomically; returns the
        paths."""

def check_program(path: _PathLike, cell: Cell) -> List[Dict[str, Any]]:
    """Reads a program (FANUC .ls main program and the programs it calls,
    KUKA .src/.dat, ABB .mod) and checks it against `cell`: joint limits,
    speeds, reachability, configuration, beads, and the set-up the cell
    file's [program] table asks for (home, dwell, interpass wait, payload,
    arc-off moves clear of the wall). Returns every problem as a
    dict (`file`, `line`, `kind`, `message`; `kind` is one of vendor,
    options, declaration, instruction, call, frame, configuration, reach,
    joint_limit, joint_speed, timing, deviation, bead, format, setup,
    collision); [] when clean. Raises WaamError when
    the file cannot be read or parsed."""
