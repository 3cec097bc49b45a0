"""How a message-based instrument is reached over the network, as VISA reaches a real one:
the raw socket (``socket.py``), HiSLIP (``hislip.py``, IVI-6.1) and VXI-11 (``vxi11.py``, ONC
RPC). Each transport serves any ``MessageInstrument`` (``device.py``); none knows SCPI. Every
listener (``tcp.py``) keeps the limits of ``wire.py`` (idle, half-open and stall timeouts, a
share of the connections per address) and tells its owner of each connection, refusal and
protocol violation; ``addresses.py`` says how an address is listened on and named."""
