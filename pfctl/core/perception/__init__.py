"""The robot's sense of people (§II-E): legs, tracking, vision, faces, clothes,
identity (Algorithm 2), the human belief (Eq. 4), and the pipeline of one tick."""
