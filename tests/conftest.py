import matplotlib

matplotlib.use("Agg")  # unit tests draw off-screen; notebook kernels keep the inline backend
