"""Inference: priors, likelihoods and engines (emcee, GA, nlopt, scipy DE)."""
