"""The ``[design]`` table of a case file (``crowdvib check``, issue 11), parsed apart from the
tables of the estimation and the simulation; every key through :class:`crowdvib.io._toml.Table`."""

from .casespecs import DesignSpec

__all__ = ["_design"]


def _design(table, path, read_msd):
    """``[design]`` → :class:`DesignSpec`; ``read_msd`` reads its ``[design.msd]`` table with the
    keys (and checks) of ``[hsi]``. The codes (and the classes given per code), the comfort class,
    the site factors, the UK NA's γ figure and the n_eq damping reading are judged where the design layer uses them (``crowdvib check``; a code
    may be registered there), not here: io imports no analysis layer (issue 26 §4)."""
    codes = table.strings("codes")
    classes_table = table.table("classes")
    classes = {"setra": classes_table.string("setra", None),
               "hivoss": classes_table.string("hivoss", None),
               "en1990": classes_table.string("en1990", None),
               "ukna": classes_table.string("ukna", None)}
    classes_table.finish()
    factors_table = table.table("site_factors")
    factors = {"k1": factors_table.raw("k1", None), "k2": factors_table.raw("k2", None),
               "k3": factors_table.raw("k3", None), "k4": factors_table.raw("k4", None)}
    for name, value in factors.items():
        if value is not None and (isinstance(value, bool)
                                  or not isinstance(value, (int, float, str))):
            raise factors_table.error(name, "must be a number or a named choice", value)
    factors = {name: value for name, value in factors.items() if value is not None}
    factors_table.finish()
    msd = None
    if table.has("msd"):
        msd_table = table.table("msd")              # the keys of [hsi]
        msd = read_msd(msd_table, path)           # the case file's own [hsi] reader
    damper = _design_damper(table.table("damper"), path) if table.has("damper") else None
    spec = DesignSpec(
        codes=codes, classes={k: v for k, v in classes.items() if v is not None},
        density=table.number("density", None, rule="positive"),
        comfort_class=table.string("comfort_class", None),
        hsi=table.boolean("hsi", True), msd=msd, site_factors=factors,
        weighting=table.string("weighting", None, choices=("Wb",)),
        gamma_figure=table.string("gamma_figure", None),
        neq_damping=table.string("neq_damping", None), damper=damper,
        prediction=table.boolean("prediction", True),
        duration=table.number("duration", 600.0, rule="positive"))
    table.finish()
    return spec


def _design_damper(table, path):
    """``[design.damper]``: an explicit damper, or a mode and mass ratio to tune one for."""
    if table.has("mode"):
        mode = table.number("mode", rule="positive")
        if int(mode) != mode:
            raise table.error("mode", "must be an integer >= 1 (1 = the first mode)", mode)
        damper = {"mode": int(mode), "mass_ratio": table.number("mass_ratio", rule="fraction")}
    else:
        damper = {"mass": table.number("mass", rule="positive"),
                  "frequency": table.number("frequency", rule="positive"),
                  "damping_ratio": table.number("damping_ratio", rule="fraction"),
                  "position": table.number("position"),
                  "lane": table.number("lane", None, rule="non_negative")}
    table.finish()
    return damper
