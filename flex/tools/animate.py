"""``flex animate``: a stored case as a video of the mechanism in its plane.

Each frame shows the mechanism seen from +z (:mod:`flex.tools.motion`): the rigid links and
the slider as outlines, each flexible link as its plate's top face, deformed and coloured by
its nodal von Mises stress (the colour scale is fixed over the whole animation; the
nonlinear FE coupler, whose stress is not recovered, is drawn grey), with the time, the
crank angle and the deformation's magnification printed on the frame.

Magnification: the deformation drawn is the elastic displacement relative to the link's
chord (the joint-face centres B and C stay on their joints, as ``<link>/midpoint_deflection``
is measured), scaled by the factor; by default the peak chord deflection of the animated
frames is drawn as 1/20 of the link length, the factor rounded down to 1, 2 or 5 x 10^k.

Output: mp4 (H.264, yuv420p) through the ffmpeg binary of the ``imageio-ffmpeg`` package
when it is installed, else an animated gif through Pillow (an ``.mp4`` asked for is then
written as ``.gif``, and stderr says so). Frames are 960 x 540 pixels. The file is written
under a temporary name and renamed when complete. A ``.png`` output is one frame (by
default at the peak stress), e.g. for a document.
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import numpy as np

from flex.base.errors import FlexError, OutputError
from flex.base.progress import heartbeat
from flex.data.outputs import check_replaceable, check_writable_folder, has_marker
from flex.dynamics.link_models import BUILTIN_LINK_MODELS, LinkModel
from flex.tools.motion import Body, CaseMotion, case_motion, top_faces

#: frame size [px] (even, as H.264 in yuv420p needs) at :data:`DPI`
SIZE_PX = (960, 540)
DPI = 100
#: the default magnification draws the peak chord deflection as this fraction of the length
DRAWN_DEFLECTION = 1 / 20
#: provenance written into every animation's metadata (PNG text, GIF comment, mp4 comment):
#: an existing output is replaced only when it carries it
MARKER = b"written by flex animate"


@dataclass
class Animation:
    """What :func:`animate_case` wrote."""

    path: Path
    frames: int
    width: int
    height: int
    fps: int
    magnification: float


def encoder_available() -> bool:
    """Whether an ffmpeg binary for mp4 is available (the ``imageio-ffmpeg`` package)."""
    try:
        import imageio_ffmpeg

        return Path(imageio_ffmpeg.get_ffmpeg_exe()).exists()
    except (ImportError, RuntimeError):
        return False


def frame_indices(count: int, frames: int) -> np.ndarray:
    """At most ``frames`` sample indices evenly spaced over ``count`` samples, first and
    last included."""
    if isinstance(frames, bool) or not isinstance(frames, int) or frames < 2:
        raise FlexError(f"--frames {frames!r}: must be an integer >= 2")
    return np.unique(np.round(np.linspace(0, count - 1, min(frames, count))).astype(int))


def nice_factor(value: float) -> float:
    """``value`` rounded down to 1, 2 or 5 x 10^k (at least 1)."""
    if not (math.isfinite(value) and value > 1):
        return 1.0
    power = 10.0 ** math.floor(math.log10(value))
    return max(step * power for step in (1, 2, 5) if step * power <= value)


def _face_nodes(body: Body) -> tuple[np.ndarray, np.ndarray]:
    x = body.reference_m[:, 0]
    tolerance = 1e-9 * np.ptp(x)
    return (np.flatnonzero(np.abs(x - x.min()) <= tolerance),
            np.flatnonzero(np.abs(x - x.max()) <= tolerance))


def _chord_frame(body: Body, position_m: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    """The chord of a flexible body at ``position_m``: origin (mean of the joint-B face
    nodes, x, y) [m], angle (toward the mean of the joint-C face nodes) [rad], and the
    nodes' in-plane positions in that frame (nodes, 2) [m]."""
    end_a, end_b = _face_nodes(body)
    b = position_m[end_a, :2].mean(axis=0)
    c = position_m[end_b, :2].mean(axis=0)
    angle = math.atan2(c[1] - b[1], c[0] - b[0])
    cos, sin = math.cos(angle), math.sin(angle)
    relative = position_m[:, :2] - b
    return b, angle, np.column_stack([cos * relative[:, 0] + sin * relative[:, 1],
                                      -sin * relative[:, 0] + cos * relative[:, 1]])


def chord_deflection(body: Body, position_m: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                                  float]:
    """A flexible body's nodes relative to its chord: the chord origin (x, y) [m], the
    nodes' in-plane displacement from their reference in the chord frame (nodes, 2) [m],
    and the chord angle [rad] (:func:`_chord_frame`; zero for a rigid motion)."""
    origin, angle, local = _chord_frame(body, position_m)
    return origin, local - _chord_frame(body, body.reference_m)[2], angle


def _drawn(body: Body, position_m: np.ndarray, magnification: float) -> np.ndarray:
    """In-plane node positions of a flexible body with its chord deflection magnified."""
    origin, deflection, angle = chord_deflection(body, position_m)
    local = _chord_frame(body, body.reference_m)[2] + magnification * deflection
    cos, sin = math.cos(angle), math.sin(angle)
    return origin + np.column_stack([cos * local[:, 0] - sin * local[:, 1],
                                     sin * local[:, 0] + cos * local[:, 1]])


@dataclass
class _Frame:
    time_s: float
    crank_angle_rad: float
    shapes: dict[str, np.ndarray]  # body -> in-plane node positions (true)
    stress: dict[str, np.ndarray | None]  # flexible body -> nodal von Mises [Pa]


def _frames(motion: CaseMotion, indices: np.ndarray) -> list[_Frame]:
    from flex.bodies.stress import von_mises

    out = []
    for index in indices:
        states = motion.states(int(index))
        out.append(_Frame(float(motion.time_s[index]), motion.crank_angle_rad(int(index)),
                          {name: state.position_m for name, state in states.items()},
                          {name: None if state.stress_Pa is None else von_mises(state.stress_Pa)
                           for name, state in states.items()}))
    return out


def _default_magnification(motion: CaseMotion, frames: list[_Frame]) -> float:
    ratios = []
    for body in motion.flexible:
        peak = max(float(np.abs(chord_deflection(body, frame.shapes[body.name])[1][:, 1]).max())
                   for frame in frames)
        length = float(np.ptp(body.reference_m[:, 0]))
        if peak > 0:
            ratios.append(DRAWN_DEFLECTION * length / peak)
    return nice_factor(min(ratios)) if ratios else 1.0


def animate_case(source: str | Path, case: str | None, out: str | Path, *, frames: int = 200,
                 fps: int = 25, magnification: float | None = None,
                 cache_dir: Path | None = None, at_time_s: float | None = None,
                 progress: Callable[[str], None] | None = None,
                 force: bool = False,
                 link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> Animation:
    """Animate ``case`` of result file ``source`` into ``out`` (``.mp4`` or ``.gif``; see the
    module doc; ``.png``: the one frame nearest ``at_time_s`` [s], by default the time of
    the first flexible link's peak von Mises stress). ``frames``: at most this many, evenly
    spaced over the stored samples; ``magnification``: the deformation scale (None: the
    default of the module doc, from those frames). Refusals (:class:`FlexError`): those of
    :func:`flex.tools.motion.case_motion`, a bad suffix, frame count, rate, time or
    magnification, an existing ``out`` that flex did not write (no :data:`MARKER` in its
    metadata; unless ``force``), a write that fails (nothing partial is left).
    ``link_models``: the registry the case's models are read from."""
    out = Path(out)
    if out.suffix.lower() not in (".mp4", ".gif", ".png"):
        raise FlexError(f"--out {out}: must end in .mp4, .gif or .png (one frame)")
    if at_time_s is not None and out.suffix.lower() != ".png":  # it was ignored
        raise FlexError(f"--time {at_time_s!r}: picks the one frame of a .png; an animation "
                        f"({out.suffix}) shows every stored time: drop --time, or write a "
                        f".png")
    if isinstance(fps, bool) or not isinstance(fps, int) or not 1 <= fps <= 120:
        raise FlexError(f"--fps {fps!r}: must be an integer in 1..120")
    if magnification is not None and not (math.isfinite(magnification) and magnification > 0):
        raise FlexError(f"--magnification {magnification!r}: must be a finite number > 0")
    if out.suffix.lower() == ".mp4" and not encoder_available():
        out = out.with_suffix(".gif")
        print(f"flex animate: no mp4 encoder (install imageio-ffmpeg): writing {out}",
              file=sys.stderr)
    frame_indices(2, frames)  # a bad --frames is refused before anything is read
    check_replaceable(out, lambda path: has_marker(path, MARKER), "flex animate: --out", force)
    check_writable_folder(out.parent, f"--out {out}")
    motion = case_motion(source, case, cache_dir=cache_dir, link_models=link_models)
    indices = frame_indices(len(motion.time_s), frames)
    drawn = _frames(motion, indices)
    factor = magnification if magnification is not None else _default_magnification(motion,
                                                                                     drawn)
    if out.suffix.lower() == ".png":
        drawn = _frames(motion, [_nearest(motion, at_time_s)])
    part = out.with_name(f".{out.stem}.{os.getpid()}.part{out.suffix}")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        _write(part, _render(motion, drawn, factor), fps)
        os.replace(part, out)
    except OSError as exc:
        raise OutputError(f"cannot write '{out}': {exc.strerror or exc}; the partial file was "
                          f"removed and no existing file was changed") from None
    finally:
        part.unlink(missing_ok=True)
    if progress:
        progress(f"flex animate: wrote {out}")
    return Animation(out, len(drawn), SIZE_PX[0], SIZE_PX[1], fps, factor)


def _nearest(motion: CaseMotion, at_time_s: float | None) -> int:
    """The motion sample nearest ``at_time_s``; None: that of the first flexible link's
    peak von Mises stress (else the middle sample)."""
    if at_time_s is None:
        at_time_s = next((float(motion.attrs[f"{b.name}_peak_von_mises_time_s"])
                          for b in motion.flexible
                          if f"{b.name}_peak_von_mises_time_s" in motion.attrs),
                         float(motion.time_s[len(motion.time_s) // 2]))
    if not (math.isfinite(at_time_s)
            and motion.time_s[0] <= at_time_s <= motion.time_s[-1]):
        raise FlexError(f"--time {at_time_s!r}: must lie in the stored times "
                        f"{motion.time_s[0]:g} .. {motion.time_s[-1]:g} s")
    return int(np.argmin(np.abs(motion.time_s - at_time_s)))


def _render(motion: CaseMotion, frames: list[_Frame], magnification: float):
    """RGB frames (height, width, 3) uint8, one per :class:`_Frame`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.tri import Triangulation

    peak = max([float(np.nanmax(s)) for f in frames for s in f.stress.values()
                if s is not None] or [1.0])
    figure = plt.figure(figsize=(SIZE_PX[0] / DPI, SIZE_PX[1] / DPI), dpi=DPI)
    axes = figure.add_axes((0.09, 0.1, 0.75, 0.8))
    bar_axes = figure.add_axes((0.87, 0.1, 0.025, 0.8))
    _limits(axes, frames, motion.scene["slider"]["offset_m"])
    faces = {body.name: top_faces(body) for body in motion.flexible}
    colour_map = matplotlib.colormaps["viridis"]
    norm = matplotlib.colors.Normalize(0.0, peak / 1e6)
    figure.colorbar(matplotlib.cm.ScalarMappable(norm, colour_map), cax=bar_axes,
                    label="von Mises stress [MPa]")
    title = f"{motion.case}: " + ", ".join(f"{b.name} {b.model}" for b in motion.bodies)
    try:
        for frame in frames:
            artists, drawn = [], {}
            for body in motion.bodies:
                xy = frame.shapes[body.name][:, :2]
                if body.kind == "rigid":
                    drawn[body.name] = xy
                    artists += axes.fill(*_outline(xy).T, **_BOX_STYLE[body.name == "slider"])
                    continue
                shape = drawn[body.name] = _drawn(body, frame.shapes[body.name], magnification)
                grid = Triangulation(shape[:, 0], shape[:, 1], faces[body.name])
                stress = frame.stress[body.name]
                if stress is None:
                    artists.append(axes.tripcolor(grid, np.zeros(len(shape)), cmap="Greys",
                                                  vmin=-1, vmax=3, shading="gouraud",
                                                  zorder=2))
                else:
                    artists.append(axes.tripcolor(grid, stress / 1e6, cmap=colour_map,
                                                  norm=norm, shading="gouraud", zorder=2))
            artists += _joints(motion, drawn, axes)
            artists.append(axes.set_title(
                f"{title}\nt = {frame.time_s * 1e3:.3f} ms, crank angle "
                f"{math.degrees(frame.crank_angle_rad):.2f} deg, deformation x "
                f"{magnification:g}", fontsize=10))
            figure.canvas.draw()
            yield np.asarray(figure.canvas.buffer_rgba())[:, :, :3].copy()
            for artist in artists[:-1]:
                artist.remove()
    finally:
        plt.close(figure)


#: rigid links (False) and the slider (True): the slider drawn light and behind the coupler,
#: so that the coupler's end and joint C stay visible on it
_BOX_STYLE = (MappingProxyType({"color": "0.7", "ec": "0.2", "lw": 1.0, "zorder": 1}),
              MappingProxyType({"color": "0.88", "ec": "0.45", "lw": 0.8, "zorder": 0.5}))


def _joints(motion: CaseMotion, drawn: dict[str, np.ndarray], axes) -> list:
    """Joints B and C (the centres of the coupler's end faces as drawn) as small circles on
    top of every body."""
    coupler = next(body for body in motion.bodies if body.name == "coupler")
    ends = [drawn["coupler"][face].mean(axis=0) for face in _face_nodes(coupler)]
    return axes.plot(*np.array(ends).T, "o", ms=5, mfc="white", mec="black", mew=1.2,
                     zorder=4, ls="none")


def _outline(xy: np.ndarray) -> np.ndarray:
    """The in-plane outline of a box body (its first four nodes: the corners at one z)."""
    return xy[[0, 1, 3, 2, 0]]


def _limits(axes, frames: list[_Frame], slide_line_y_m: float) -> None:
    points = np.vstack([shape[:, :2] for frame in frames for shape in frame.shapes.values()])
    low, high = points.min(axis=0), points.max(axis=0)
    pad = 0.08 * float(np.max(high - low))
    axes.set_xlim(low[0] - pad, high[0] + pad)
    axes.set_ylim(low[1] - pad, high[1] + pad)
    axes.set_aspect("equal", adjustable="box")
    axes.set_xlabel("x [m]")
    axes.set_ylabel("y [m]")
    axes.plot([low[0] - pad, high[0] + pad], [slide_line_y_m] * 2, color="0.85", lw=0.8,
              zorder=0)  # the slide line
    axes.plot([0.0], [0.0], "k^", ms=8)  # the crank pivot A


def _write(path: Path, frames, fps: int) -> None:
    """Encode RGB frames to ``path`` (mp4 through imageio-ffmpeg, else gif)."""
    if path.suffix.lower() == ".mp4":
        import imageio_ffmpeg

        writer = imageio_ffmpeg.write_frames(str(path), SIZE_PX, fps=fps, codec="libx264",
                                             pix_fmt_out="yuv420p", macro_block_size=1,
                                             ffmpeg_log_level="error", output_params=[
                                                 "-metadata", f"comment={MARKER.decode()}"])
        writer.send(None)
        try:
            for frame in frames:
                writer.send(np.ascontiguousarray(frame))
        finally:
            writer.close()
        return
    from PIL import Image

    if path.suffix.lower() == ".png":
        from PIL.PngImagePlugin import PngInfo

        info = PngInfo()
        info.add_text("Software", MARKER.decode())
        Image.fromarray(next(iter(frames))).save(path, format="PNG", optimize=True,
                                                 pnginfo=info)
        return
    images = [Image.fromarray(frame).quantize(colors=255) for frame in frames]
    images[0].save(path, format="GIF", save_all=True, append_images=images[1:],
                   duration=round(1000 / fps), loop=0, comment=MARKER)


def default_animation_path(result: Path, case: str) -> Path:
    """``figures/<stem>-<case>.mp4`` (``.gif`` without an encoder) beside ``result``."""
    suffix = ".mp4" if encoder_available() else ".gif"
    return result.parent / "figures" / f"{result.stem}-{case}{suffix}"


def animate_results(result: str | Path, *, cache_dir: Path | None = None,
                    frames: int = 200) -> Iterator[Animation]:
    """Animate every ok case with a flexible link of a result file
    (:func:`default_animation_path`), yielding each animation once it is written (``flex run
    --animate``)."""
    from flex.data.results import attribute_value, case_names, reading
    from flex.tools.motion import case_scene, motion_problem

    result = Path(result)
    chosen = []
    with reading(result) as h5:
        for name in case_names(h5):
            attrs = {k: attribute_value(v) for k, v in h5[f"cases/{name}"].attrs.items()}
            if attrs.get("status") != "ok":
                continue
            problem = motion_problem(case_scene(attrs, f"{result} case {name}"))
            if not problem:
                chosen.append(name)
            elif not problem.startswith("no flexible link"):  # said, not skipped silently
                print(f"flex: note: case {name} is not animated: {problem}", file=sys.stderr,
                      flush=True)
    # figures/ beside a result file is flex's own folder: a run replaces its figures there
    for name in chosen:
        path = default_animation_path(result, name)
        # a phase named, then a line every few seconds: "still working (last line: [1/1]
        # done)" was all stderr said for 37 s
        print(f"flex: animating case {name} -> {path}", file=sys.stderr, flush=True)
        with heartbeat(f"animating case {name}"):
            done = animate_case(result, name, path, frames=frames, cache_dir=cache_dir,
                                force=True)
        yield done


__all__ = ["Animation", "animate_case", "animate_results", "chord_deflection",
           "default_animation_path", "encoder_available", "frame_indices", "nice_factor"]
