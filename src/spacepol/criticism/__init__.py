"""Model criticism: where the model fails (residual structure, PPC, LOO) and what is missing."""
