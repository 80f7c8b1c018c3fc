"""What every test of the package needs."""

import signal

# The Ctrl-C tests need Python's own SIGINT handler. A run started in the
# background by a non-interactive shell (`cmd &`, nohup) inherits SIGINT
# ignored, and Python leaves it so: interrupt_main() then does nothing, and
# an interpreter started from the tests ignores SIGINT too (all seven
# Ctrl-C tests failed so). Installed here, the handler is what an
# interactive run has, and the processes the tests start get the default
# disposition (a handled signal is reset at exec; an ignored one is not).
signal.signal(signal.SIGINT, signal.default_int_handler)
