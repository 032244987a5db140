"""Parameter sweeps and ensembles of yarnsim's FMUs on Dask."""
from .spec import Sweep, SweepError
from .runner import run_sweep, connect

__version__ = "0.1.0"
__all__ = ["Sweep", "SweepError", "run_sweep", "connect"]
