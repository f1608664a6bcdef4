"""The time-domain forward model: Monte Carlo with moving pedestrians (docs: theory, The coupled
time-domain model).

``traffic`` (the pedestrians' arrivals), ``simulation`` (a run checked into ``_run``, stepped by
``_integrator`` with the compiled kernel of ``_kernels``), ``simulation_psd`` (the Welch PSD of a
record too long to keep), ``batch`` (many seeded records) and ``replay`` (the people and MSDs of
a run, for the animation); their results are in ``results``, their figures in ``plots``.
"""

from .batch import simulate_many
from .results import Simulation, SimulationPSD
from .simulation import simulate
from .simulation_psd import simulate_psd
from .traffic import Pedestrian, generate_traffic

__all__ = ["simulate", "simulate_many", "simulate_psd", "Pedestrian", "generate_traffic",
           "Simulation", "SimulationPSD"]
