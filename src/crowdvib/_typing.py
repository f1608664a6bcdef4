"""Type aliases of the public API's hints (for type checkers only: nothing here runs)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Union

if TYPE_CHECKING:
    import numpy as np

    from .models.loading import ForceModel as _ForceProtocol
    from .models.measured import MeasuredForce

    #: A walking-force model: any models.loading.ForceModel (the harmonic models, a user's) or
    #: measured forces replayed.
    ForceModel = Union[_ForceProtocol, MeasuredForce]
    #: A seed or a generator: every random draw of crowdvib flows from one.
    Seed = Union[int, np.random.Generator, None]
