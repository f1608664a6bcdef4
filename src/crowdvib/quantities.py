"""The vocabulary of quantities: a JSON key of results and case files → words and SI unit.

One table for everything that names a quantity to a reader: the results
(:meth:`crowdvib.HSIEstimate.summary`), the HTML report's labels, the case-file key reference and
the docs built from it (issue 26 §4).
Units are SI with frequencies in Hz; "-" marks a dimensionless quantity (a fraction).
"""

from types import MappingProxyType

__all__ = ["QUANTITIES", "describe", "unit"]

#: JSON key → (words, unit) for a reader; read-only, so every user sees the same table.
QUANTITIES = MappingProxyType({
    "frequency": ("frequency", "Hz"), "frequencies": ("natural frequencies", "Hz"),
    "damping_ratio": ("damping ratio", "-"), "damping_ratios": ("damping ratios", "-"),
    "mass_ratio": ("mass ratio", "-"), "modal_masses": ("modal masses", "kg"),
    "modal_mass": ("modal mass", "kg"), "modal_mass_ratios": ("crowd-to-mode mass ratios", "-"),
    "length": ("walkway length", "m"), "span": ("span", "m"), "width": ("walkway width", "m"),
    "n_lanes": ("lanes", "-"), "density": ("crowd density", "persons/m²"),
    "density_uncertainty": ("relative standard uncertainty of the crowd density", "-"),
    "walking_speed": ("walking speed", "m/s"),
    "step_frequency_mean": ("mean step frequency", "Hz"),
    "step_frequency_std": ("step-frequency spread", "Hz"), "body_mass": ("body mass", "kg"),
    "body_mass_std": ("body-mass spread", "kg"),
    "forward_fraction": ("walkers in the forward direction", "-"),
    "sample_rate": ("sample rate", "Hz"), "record_sample_rate": ("stored sample rate", "Hz"),
    "time_frame": ("time frame", "s"), "lowpass_cutoff": ("low-pass cut-off", "Hz"),
    "lowpass_order": ("low-pass order", "-"), "window_length": ("Welch window T", "s"),
    "max_gap": ("longest dropout bridged", "s"), "header_row": ("header row (line)", "-"),
    "overlap": ("window overlap", "-"), "band": ("analysis band", "Hz"),
    "cutoff": ("low-pass cut-off", "Hz"), "duration": ("duration", "s"),
    "duration_s": ("duration", "s"), "warm_up": ("warm-up", "s"),
    "rms": ("RMS acceleration", "m/s²"), "elapsed_s": ("run time", "s"),
    "n_windows": ("Welch windows", "-"), "level": ("confidence level", "-"),
    "output_weights": ("output weights γ", "-"), "weights": ("output weights γ", "-"),
    "n_samples": ("samples", "-"), "start_time": ("start time", "s"),
    "starts": ("starting points (f_h1, ξ_h1[, μ_h1])", "Hz, -, -"),
    "mean_on_deck": ("mean number on the deck", "-"), "n_pedestrians": ("pedestrians", "-"),
    "time_step": ("time step", "s"), "peak": ("peak acceleration", "m/s²"),
    "k4": ("exposure factor k4", "-"), "n_boot": ("bootstrap refits", "-"),
    # operational modal analysis (crowdvib modes)
    "frequency_band": ("frequency band", "Hz"), "n_modes": ("number of modes", "-"),
    "block_rows": ("SSI-cov block rows", "-"), "max_order": ("highest model order", "-"),
    "decimation": ("decimation factor", "-"), "n_blocks": ("data blocks for σ", "-"),
    "segment_length": ("Welch segment", "samples"), "mac_threshold": ("MAC threshold", "-"),
    "groups": ("jackknife groups", "-"),
    # a year of comfort (crowdvib comfort: [comfort], [traffic])
    "rms_window": ("running RMS window", "s"), "damper_mass_ratio": ("damper mass ratio", "-"),
    "densities": ("densities of the response table", "-"),
    "resamples": ("resamples of the season's windows", "-"),
    "hours_per_year": ("hours a year", "h"), "days": ("days a year", "d"),
    "year_hours": ("hours of the year", "h"),
    "profile": ("crowd density by hour of the day", "persons/m²"),
    "simulate_below": ("simulated windows below the density", "persons/m²"),
    "simulated_windows": ("simulated windows per density", "-"),
})


def unit(key: str) -> str | None:
    """The SI unit of a JSON key ("-" dimensionless), or None for a key the table does not hold."""
    entry = QUANTITIES.get(str(key))
    return None if entry is None else entry[1]


def describe(key: str) -> str:
    """A JSON key as words with the unit, e.g. "walking speed [m/s]"; an unknown key as its words."""
    key = str(key)
    if key in QUANTITIES:
        words, symbol = QUANTITIES[key]
        return f"{words} [{symbol}]"
    return key.replace("_", " ")
