"""The lab front: the rig as lab clients see it (scenes as the shot sources of virtual
instruments, ophyd-async devices for bluesky)."""
