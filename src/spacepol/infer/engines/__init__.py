"""The engines, one module each (emcee, NUTS, the paper's GA, scipy DE, nlopt), the interface they share
(``base.Engine``) and their small registered classes (``builtin``); ``infer.engine_registry`` finds them by name."""
