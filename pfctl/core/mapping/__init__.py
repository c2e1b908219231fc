"""Maps (§II-B/C/D): occupancy grid (Eq. 1), frontiers (Eq. 2, Eq. 3), regions and
Algorithm 1, rooms, walls, path lengths, planning."""
