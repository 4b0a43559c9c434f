"""Power curves and design sweeps of the pumping cycle on Dask.

- :mod:`.spec`: sweep axes, points (stable ids), warm-start chains;
- :mod:`.design`: glider variants (folded span, folded drag area, wing area) from the definitions;
- :mod:`.runner`: one point = one periodic-cycle OCP (what a Dask worker runs);
- :mod:`.store`: one JSON file per finished point (resume without recomputation);
- :mod:`.execute`: Dask execution (embedded LocalCluster or ``tcp://`` scheduler), progress bar;
- :mod:`.references`: Loyd and quasi-steady reel-out reference curves;
- :mod:`.outputs`: CSV, power-curve plot, "where folding pays" map, markdown summary;
- :mod:`.report`: all outputs of a finished sweep in one call.
"""

import sys as _sys

from .. import CallableModule

# ``fdm_awe.sweep(...)`` is the Python API's sweep (fdm_awe.api.sweep); the package stays a package
_sys.modules[__name__].__class__ = CallableModule
