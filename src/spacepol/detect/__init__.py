"""Detectability of a target against the daytime sky: scenario, radiometry (eqs 34-39), contrast."""
