"""Design codes as peers: each is one object, registered under its name, behind one interface.

:func:`crowdvib.design.design_check` validates what every code shares (the structure, the crowd,
the MSD, the dampers), looks the code up here and hands it the rest. A code is a
:class:`DesignCode`: a ``name``, the keyword ``options`` of ``design_check`` it understands
(any other one given is refused, not ignored) and a ``check`` method returning a
:class:`~crowdvib.design.DesignCheck`. The built-in codes register themselves when
:mod:`crowdvib.design` is imported (Sétra, HiVoSS and EN 1990 in :mod:`.check`, the UK NA in
:mod:`.ukna`); a new code is one module that subclasses :class:`DesignCode` and calls
:func:`register_code`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, ClassVar

from ..errors import ParameterError

if TYPE_CHECKING:
    from .check import DesignCheck

__all__ = ["DesignCode", "register_code", "unregister_code", "design_code", "code_names",
           "code_label"]

#: The keyword options of design_check a code may take, beyond the shared inputs.
OPTIONS = ("comfort_class", "site_factors", "weighting", "neq_damping", "gamma_figure")


class DesignCode(ABC):
    """One design code: its name, the options it takes and its check.

    Attributes
    ----------
    name : str
        The name ``design_check`` is called with.
    label : str
        The code's name in words, as reports and verdicts write it (default: ``name``).
    options : frozenset of str
        The options of :data:`OPTIONS` the code understands.
    unverified_defaults : tuple of str
        The code's defaults that were not verified against its guide, in words
        (:data:`crowdvib.design.codes.UNVERIFIED_DEFAULTS` for the built-in codes);
        :func:`~crowdvib.design.design_check` writes them into every result's
        ``details["unverified_defaults"]``, and the report lists them with the inputs.
    """

    name: ClassVar[str] = ""
    label: ClassVar[str] = ""
    options: ClassVar[frozenset] = frozenset()
    unverified_defaults: tuple = ()

    @abstractmethod
    def check(self, structure, *, traffic_class, density, crowd, msd, dampers,
              **options) -> DesignCheck:
        """The comfort check (inputs shared by all codes already validated by design_check;
        ``dampers`` a tuple of TunedMassDamper; ``options`` only those given, not None).

        Parameters
        ----------
        structure : ModalModel
            The empty bridge.
        traffic_class : str or None
            The code's class, if given.
        density : float
            Crowd density of the check [persons/m²].
        crowd : Crowd
            The walkers at that density.
        msd : MSDModel or None
            The pedestrians' MSD for the check with HSI.
        dampers : tuple of TunedMassDamper
            Dampers on the deck.
        **options
            The code's own options of :func:`~crowdvib.design.design_check` that were given.

        Returns
        -------
        DesignCheck
        """


_CODES: dict[str, DesignCode] = {}


def register_code(code: DesignCode, *, replace: bool = False) -> DesignCode:
    """Make ``code`` available to :func:`crowdvib.design.design_check` under ``code.name``.

    Parameters
    ----------
    code : DesignCode
        The code; its ``options`` must be among the keyword options of ``design_check``.
    replace : bool
        Replace a code already registered under the same name (refused otherwise).

    Returns
    -------
    DesignCode
        ``code``, so that the call can decorate a class's instance.

    Raises
    ------
    ParameterError
        Not a DesignCode, an empty name, an unknown option, or a name already taken.

    See Also
    --------
    unregister_code, code_names, design_check
    """
    if not isinstance(code, DesignCode):
        raise ParameterError(f"code must be a DesignCode instance, got {type(code).__name__}")
    if not isinstance(code.name, str) or not code.name:
        raise ParameterError(f"a design code's name must be a non-empty str, got {code.name!r}")
    unknown = sorted(set(code.options) - set(OPTIONS))
    if unknown:
        raise ParameterError(f"design code {code.name!r}: options must be among {list(OPTIONS)}, "
                             f"got {unknown}")
    if code.name in _CODES and not replace:
        raise ParameterError(f"design code {code.name!r} is already registered; pass "
                             "replace=True to replace it")
    _CODES[code.name] = code
    return code


def unregister_code(name: str) -> None:
    """Remove a registered code (a plug-in's or a test's).

    Parameters
    ----------
    name : str
        The code's name; an unregistered name is a ParameterError.
    """
    design_code(name)
    del _CODES[name]


def design_code(name: str) -> DesignCode:
    """The registered code called ``name``."""
    if name not in _CODES:
        raise ParameterError(f"code must be one of {list(_CODES)}, got {name!r}")
    return _CODES[name]


def code_label(name: str) -> str:
    """A code's name in words (``"UK NA"`` for ``"ukna"``): its ``label``, else ``name``, also
    for a code no longer registered (a results file read back keeps its names).

    Parameters
    ----------
    name : str
        The code's name.
    """
    code = _CODES.get(name)
    return (code.label or code.name) if code is not None else str(name)


def code_names() -> tuple:
    """Names of the registered codes, in registration order."""
    return tuple(_CODES)
