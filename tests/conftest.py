import os

os.environ.setdefault("JSBSIM_DEBUG", "0")
os.environ.setdefault("MPLBACKEND", "Agg")
