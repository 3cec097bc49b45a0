"""The compiler of every kernel of the project, beneath both ``rig`` and ``instruments``
(it imports neither): ``jit.py`` the one numba decorator and the guard that keeps a kernel
package's on-disk cache consistent with its sources; ``dispatcher.py`` the kernels' numba
dispatcher, one compiled copy per argument type, and whether the cache holds a kernel's
machine code."""
