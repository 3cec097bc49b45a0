"""Many VISA clients at once, for the transports' tests."""
import threading


def talk_at_once(sessions, queries: int = 25) -> dict:
    """Every pyvisa session in ``sessions`` asks ``ECHO? k-i`` ``queries`` times, all starting
    together on threads of their own; {k: the replies of session k}."""
    results, start = {}, threading.Barrier(len(sessions))

    def client(k):
        start.wait()
        results[k] = [sessions[k].query(f"ECHO? {k}-{i}") for i in range(queries)]

    threads = [threading.Thread(target=client, args=(k,)) for k in range(len(sessions))]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    return results
