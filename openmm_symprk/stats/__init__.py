"""Error bars for molecular-dynamics time series (numpy; pymbar for the correlation part).

One place for the statistics every study, the bench and the reporters use:

* :mod:`.timeseries` -- statistical inefficiency and the end of an initial transient (pymbar's
  ``timeseries``), mean and standard error of a correlated series (from the inefficiency, or from block means);
* :mod:`.slope` -- the energy drift: the least-squares slope of y(t) with its standard error (correlated
  residuals), in one pass over stored samples or with O(1) work per new sample (:class:`.slope.RunningLine`);
* :mod:`.compare` -- replicas combined into one estimate, and the agreement of two rows (paired by replica);
* :mod:`.jackknife` -- the delete-one-group jackknife: the error of a non-linear figure of an average over
  molecules (a correlation time) or replicas.
"""
from .compare import Estimate, agrees, combine, difference, no_larger, paired
from .jackknife import jackknife
from .slope import Drift, RunningLine, drift
from .timeseries import SeriesStats, block_stats, equilibrated_from, series_stats, statistical_inefficiency

__all__ = ["Estimate", "agrees", "combine", "difference", "no_larger", "paired", "Drift", "RunningLine", "drift",
           "jackknife", "SeriesStats", "block_stats", "equilibrated_from", "series_stats", "statistical_inefficiency"]
