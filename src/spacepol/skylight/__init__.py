"""The daytime sky: the sun's position (astropy), sky polarization models, hemisphere projections."""
