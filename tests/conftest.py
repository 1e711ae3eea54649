import os

# numpy and scipy each start an OpenBLAS pool; on small machines that slows eigsh several-fold.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
