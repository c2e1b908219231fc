"""The wiring: mission → parameters → core objects and a backend; episode runners,
learn-target procedures, perception set-up, leg data sets (DESIGN.md)."""
