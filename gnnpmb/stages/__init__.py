"""The stages one command's data passes through, each a function of the one before and none calling back.

``request`` (checked arguments) → ``inputs`` (scene slice, detections, results files, parameters) → ``runs`` (every
tracker run once: its output, events and facts) → ``evaluation`` (the devkit's failures of every run) →
``findings`` (explanations, the focus as a selection of failures, the comparison) → outputs: a recording
(``viz.view``), a terminal table (``cli``), JSON (``why.serialize``). ``diff`` is two runs through the same stages.
A stage imports only the stages before it (``docs/architecture.md``).
"""
