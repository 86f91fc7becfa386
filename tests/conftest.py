"""Shared test set-up: hypothesis profiles.

`ci` (selected by .ci/run and tools/test.sh with --hypothesis-profile=ci) is
derandomised and keeps no example database, so CI runs are reproducible;
`dev` runs more examples for local hunting.
"""
from hypothesis import HealthCheck, settings

settings.register_profile("ci", deadline=None, print_blob=True, derandomize=True,
                          database=None, max_examples=200,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("dev", deadline=None, print_blob=True, max_examples=1000)
settings.register_profile("default", deadline=None, print_blob=True)
