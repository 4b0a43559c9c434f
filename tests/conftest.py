import os

os.environ.setdefault("JSBSIM_DEBUG", "0")
os.environ.setdefault("MPLBACKEND", "Agg")
# the tests' many small NLPs are not written to the user's on-disk NLP cache (its own tests
# switch it on in a temporary folder)
os.environ.setdefault("FDM_AWE_NLP_CACHE", "off")
