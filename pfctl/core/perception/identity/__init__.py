"""Target identification, Algorithm 2 (§II-E): legs, then face, then clothes."""
