"""The course's Jupyter server settings, read by `make lab` (JUPYTER_CONFIG_PATH=jupyter_config).

Your own ~/.jupyter settings still apply and win over these. Each line below removes a
message a student would otherwise meet on the first launch; the README says what remains.
"""

c = get_config()  # noqa: F821 (provided by Jupyter when it reads this file)

# Encrypt the kernel's connection (CurveZMQ keys made by the server): ipykernel declares
# support, so every kernel runs encrypted and no longer warns "running over TCP without
# encryption". Kernels whose kernelspec does not declare it start as before.
c.KernelManager.transport_encryption = "auto"

# No language servers are installed for the course: do not scan for the ~30 known ones
# (each launch printed the list of those it skipped).
c.LanguageServerManager.autodetect = False

# Voila is installed for `make present`, which runs it on its own; its JupyterLab preview
# is not used. Not loading it into JupyterLab also keeps it from turning on traitlets'
# deprecation warnings (a "ServerApp.token config is deprecated" line on every launch).
c.ServerApp.jpserver_extensions = {"voila.server_extension": False}

# jupyter_server asks tornado for a websocket ping timeout (90000) longer than its ping
# interval (30000); tornado then warns on every kernel connection and uses 30000. Ask for
# what tornado will use anyway.
c.ServerApp.tornado_settings = {"ws_ping_timeout": 30000}
