"""Target identification, Algorithm 2 (§II-E): legs, then face, then clothes.

- :mod:`~pfctl.core.perception.identity.params`: its thresholds and measuring schedule;
- :mod:`~pfctl.core.perception.identity.profile`: appearances and the target's profile;
- :mod:`~pfctl.core.perception.identity.identifier`: the decision per track, kept over time.
"""
