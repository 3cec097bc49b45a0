"""Pictures: figures (matplotlib) and off-screen animations (pyvista, an optional extra)."""
