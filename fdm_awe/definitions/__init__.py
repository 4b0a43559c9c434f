"""Loading and validation of the definition files (aircraft, engine, ground station).

The XML files under ``aircraft/``, ``engine/`` and ``tether/`` are the single source of
truth; everything in Python reads them through this package into typed, SI parameter
objects.
"""
