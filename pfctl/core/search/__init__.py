"""Looking for a lost (or never seen) target: where she can be (:mod:`.whereabouts`, a belief
over the home's regions fed by the camera's empty looks, Eq. 4) and where to look next
(:mod:`.next_look`, Algorithm 1's places chosen by probability over time)."""
