"""Hand synergies in grasp-force planning: hand, synergies, objects, closure, mechanics, force optimisation, minima, figures."""
