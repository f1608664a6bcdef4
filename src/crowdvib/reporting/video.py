"""The crossing replay as a video file for slides (issue 38): GIF through Pillow, MP4 through
ffmpeg where it is installed, with matplotlib's animation writers.

The frames are the replay's (:class:`~crowdvib.response.time_domain.replay.Replay`), every n-th one for the
video's frame rate; the picture is the report's: the deck in plan with its walkers, the deck's
deflection (exaggerated, the scale in the title) with the walkers on it (with HSI each one
lifted by its MSD's displacement relative to the deck, at the same scale), and the
acceleration at the first output with a moving cursor and the comfort classes' bounds.
"""

from pathlib import Path

import numpy as np

from ..design.codes import COMFORT_CLASSES
from ..errors import DataError, ParameterError
from .._files import atomic_path

__all__ = ["write_replay_video", "VIDEO_FRAME_RATE"]

#: Frames per second of a video (a 30 s replay: 300 frames; a slide needs no more).
VIDEO_FRAME_RATE = 10.0
_COLOURS = ("#1f4e79", "#c0392b")


def write_replay_video(replay, structure, path, *, fps=VIDEO_FRAME_RATE, dpi=80):
    """Write ``replay`` as a GIF or MP4 file.

    Parameters
    ----------
    replay : Replay
        From :func:`~crowdvib.response.time_domain.replay.crossing_replay`.
    structure : ModalModel
        The model it was simulated on.
    path : str or pathlib.Path
        ``.gif`` (Pillow) or ``.mp4`` (ffmpeg); written atomically.
    fps : float
        Frames per second of the video (at most the replay's; every n-th frame is kept).
    dpi : int
        Resolution of the 8 × 5 inch picture.

    Returns
    -------
    int
        The number of frames written.

    Raises
    ------
    ParameterError
        Another suffix, or a non-positive ``fps``.
    DataError
        MP4 asked for where ffmpeg is not installed (the message says what to do).
    """
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import animation
    import matplotlib.pyplot as plt


    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise ParameterError(f"path {path.name}: a replay video is a .gif or .mp4 file")
    if not fps > 0:
        raise ParameterError(f"fps must be > 0, got {fps!r}")
    if suffix == ".mp4" and not animation.writers.is_available("ffmpeg"):
        raise DataError(f"{path.name}: an MP4 needs ffmpeg, which is not installed here "
                        "(apt-get install ffmpeg, or conda install ffmpeg); a .gif needs "
                        "nothing more")
    # The frame rate to a micro-hertz (20.00000000002 would make GIF frames of 99 ms, stored as
    # 9 centiseconds).
    rate = round(1.0 / (replay.time[1] - replay.time[0]), 6) if replay.n_frames > 1 else fps
    every = max(1, int(round(rate / fps)))
    frames = np.arange(0, replay.n_frames, every)
    figure, draw, moving = _picture(replay, structure, plt)
    writer = (_blitting_gif_writer(animation, moving)(fps=rate / every) if suffix == ".gif"
              else animation.FFMpegWriter(fps=rate / every))
    try:
        with atomic_path(path) as temporary:
            # The writers choose the format by the suffix: written under it, then moved.
            target = Path(temporary).with_suffix(suffix)
            try:
                with writer.saving(figure, str(target), dpi):
                    for k in frames:
                        draw(k)
                        writer.grab_frame()
                target.replace(temporary)
            finally:
                target.unlink(missing_ok=True)
    finally:
        plt.close(figure)
    return int(frames.size)


def _blitting_gif_writer(animation, moving):
    """matplotlib's Pillow writer drawing only the ``moving`` artists over the still picture
    (its ``grab_frame`` draws the whole figure twice a frame: some 0.5 s, ten times this), each
    frame quantised to the first frame's palette (the colours do not change)."""
    from PIL import Image

    class Writer(animation.PillowWriter):
        def setup(self, fig, outfile, dpi=None):
            super().setup(fig, outfile, dpi=dpi)
            fig.set_dpi(self.dpi)
            for artist in moving:
                artist.set_animated(True)
            fig.canvas.draw()
            self._still = fig.canvas.copy_from_bbox(fig.bbox)
            self._palette = None

        def grab_frame(self, **savefig_kwargs):
            canvas = self.fig.canvas
            canvas.restore_region(self._still)
            for artist in moving:
                self.fig.draw_artist(artist)
            size = canvas.get_width_height()
            image = Image.frombuffer("RGBA", size, bytes(canvas.buffer_rgba()), "raw",
                                     "RGBA", 0, 1).convert("RGB")
            if self._palette is None:
                self._palette = image.quantize(colors=96, method=Image.Quantize.MEDIANCUT)
            self._frames.append(image.quantize(palette=self._palette,
                                               dither=Image.Dither.NONE))

    return Writer


def _picture(replay, structure, plt):
    """The figure, its ``draw(frame)`` and the artists that move."""
    x = np.linspace(structure.positions[0], structure.positions[-1], 101)
    shapes = structure.shapes_at(x)
    deflection = shapes @ replay.modal_displacement                  # station × frame [m]
    largest = float(np.max(np.abs(deflection))) or 1.0
    span = x[-1] - x[0]
    scale = 0.08 * span / largest                                     # drawn / true
    figure, (plan, elevation, trace) = plt.subplots(
        3, 1, figsize=(8, 5), gridspec_kw={"height_ratios": (1, 1.6, 1.6)})
    plan.set(xlim=(x[0], x[-1]), ylim=(0, structure.width), yticks=[], ylabel="plan")
    plan.set_title(f"deflection × {scale:.3g} (largest {1e3 * largest:.3g} mm); "
                   f"seed {replay.seed}", fontsize=9, loc="left")
    elevation.set(xlim=(x[0], x[-1]), ylim=(-0.13 * span, 0.13 * span), ylabel="elevation",
                  yticks=[])
    elevation.set_aspect("auto")
    elevation.axhline(0.0, color="0.6", lw=0.8, ls="--")
    deck, = elevation.plot(x, scale * deflection[:, 0], color="#1b1f24", lw=2.5)
    people = elevation.scatter([], [], s=9)
    above = plan.scatter([], [], s=7)
    output = 0
    trace.plot(replay.trace_time, replay.acceleration[output], color="#1f4e79", lw=0.6)
    reach = max(float(np.max(np.abs(replay.acceleration[output]))), COMFORT_CLASSES[0][1])
    for name, bound in (c for c in COMFORT_CLASSES[:2] if c[1] <= 1.15 * reach):
        for sign in (1, -1):
            trace.axhline(sign * bound, color="#c47f00", lw=0.8, ls="--")
        trace.text(replay.trace_time[-1], bound, f"{name} ±{bound:g}", ha="right",
                   va="bottom", fontsize=7, color="#c47f00")
    trace.set(xlim=(replay.trace_time[0], replay.trace_time[-1]), ylim=(-1.15 * reach,
                                                                        1.15 * reach),
              xlabel="time [s]", ylabel=f"a at {replay.output_names[output]} [m/s²]")
    cursor = trace.axvline(replay.time[0], color="#c0392b", lw=1.2)
    label = plan.text(0.99, 1.04, "", transform=plan.transAxes, ha="right", fontsize=9)
    figure.tight_layout()

    def draw(k):
        t = replay.time[k]
        drawn = scale * deflection[:, k]
        deck.set_ydata(drawn)
        on, positions = replay.positions(t)
        colours = [_COLOURS[0 if v >= 0 else 1] for v in replay.velocity[on]]
        lift = 0.012 * span
        if replay.msd_displacement is not None:       # the MSD's body against the deck
            lift = lift + scale * np.nan_to_num(replay.msd_displacement[on, k])
        people.set_offsets(np.c_[positions, np.interp(positions, x, drawn) + lift])
        people.set_color(colours)
        above.set_offsets(np.c_[positions, replay.lateral[on]])
        above.set_color(colours)
        cursor.set_xdata([t, t])
        label.set_text(f"t = {t:6.2f} s, {on.size} on the deck")

    return figure, draw, (deck, people, above, cursor, label)
