"""The report's analyses: one module per section (``TITLE``, ``ORDER``, ``build``)."""
