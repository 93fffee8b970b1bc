"""The validation suites: renders with a hidden effect that ``diagnose`` must name (``hidden_effects``) and renders
whose shadowing was swapped that ``diagnose --rounds`` must repair (``swap_suite``); scored, summarised and drawn.
The library's own checks of itself, kept apart from the library."""
