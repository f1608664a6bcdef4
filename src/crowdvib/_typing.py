"""Type aliases of the public API's hints (for type checkers only: nothing here runs)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Union

if TYPE_CHECKING:
    import numpy as np

    from .models.loading import YoungForce, ZivanovicForce
    from .models.measured import MeasuredForce

    #: A walking-force model: the harmonic models or measured forces replayed.
    ForceModel = Union[ZivanovicForce, YoungForce, MeasuredForce]
    #: A seed or a generator: every random draw of crowdvib flows from one.
    Seed = Union[int, np.random.Generator, None]
