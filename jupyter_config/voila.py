"""The course's Voila settings, read by `make present` (JUPYTER_CONFIG_PATH=jupyter_config)."""

c = get_config()  # noqa: F821 (provided by Jupyter when it reads this file)

# Encrypted kernel connections (see jupyter_server_config.py): no "TCP without encryption".
c.KernelManager.transport_encryption = "auto"
# Ask tornado for the websocket ping timeout it would fall back to anyway (no warning).
c.Voila.tornado_settings = {"ws_ping_timeout": 30000}
# Lecture mode shows results, not code or tracebacks.
c.VoilaConfiguration.strip_sources = True
c.VoilaConfiguration.show_tracebacks = False
