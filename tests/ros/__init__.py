"""ROS 1 tests. A package so that its conftest is ``ros.conftest``, not a second top-level
``conftest`` that would shadow ``tests/conftest.py`` for ``from conftest import ...``."""
