"""Human and machine-readable results: tables, CSV/JSON, VTU meshes and PNG mode-shape pictures."""
