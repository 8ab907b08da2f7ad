"""feedoracle's heuristic side: NC programs, machine data, path preparation and the
SINUMERIK-style reference planner. Kept light: ``reference.core`` imports run this file.
"""
