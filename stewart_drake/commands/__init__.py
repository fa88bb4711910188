"""One module per ``stewart-drake`` subcommand; each defines ``register(subparsers)``."""
