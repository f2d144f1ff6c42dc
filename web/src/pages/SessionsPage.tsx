import { useEffect, useState } from 'react';
import { Api, ApiFailure } from '../api/http';
import { ErrorBox } from '../components/ErrorBox';
import { formatClock } from '../logic/replay';
import type { SessionList } from '../types';

const PAGE = 25;

export function SessionsPage({ api }: { api: Api }) {
  const [offset, setOffset] = useState(0);
  const [list, setList] = useState<SessionList | null>(null);
  const [failure, setFailure] = useState<ApiFailure | null>(null);

  useEffect(() => {
    let live = true;
    api
      .sessions(PAGE, offset)
      .then((l) => live && setList(l))
      .catch((e: unknown) => live && e instanceof ApiFailure && setFailure(e));
    return () => {
      live = false;
    };
  }, [api, offset]);

  return (
    <div className="page sessions">
      <h1>Sessions</h1>
      <ErrorBox failure={failure} />
      {!list ? (
        <p className="muted">Loading…</p>
      ) : list.sessions.length === 0 ? (
        <p>No sessions yet: a session opens when a drone is connected.</p>
      ) : (
        <>
          <table data-testid="sessions">
            <caption className="sr-only">Control sessions, newest first</caption>
            <thead>
              <tr>
                <th scope="col">#</th>
                <th scope="col">Date</th>
                <th scope="col">Duration</th>
                <th scope="col">Drone</th>
                <th scope="col">Commands</th>
                <th scope="col">Alerts</th>
                <th scope="col">
                  <span className="sr-only">Actions</span>
                </th>
              </tr>
            </thead>
            <tbody>
              {list.sessions.map((s) => (
                <tr key={s.id}>
                  <td>{s.id}</td>
                  <td>
                    <time dateTime={s.started_at}>{new Date(s.started_at).toLocaleString()}</time>
                    {s.open && <span className="badge badge-info">open</span>}
                  </td>
                  <td>{formatClock(s.duration_s * 1000)}</td>
                  <td>{s.drone}</td>
                  <td>{s.command_count}</td>
                  <td>{s.alert_count}</td>
                  <td>
                    <a href={`#/sessions/${s.id}`} aria-label={`Replay session ${s.id}`}>
                      Replay
                    </a>
                  </td>
                </tr>
              ))}
            </tbody>
          </table>
          <div className="row pager">
            <button
              type="button"
              disabled={offset === 0}
              onClick={() => setOffset(Math.max(0, offset - PAGE))}
            >
              Newer
            </button>
            <span>
              {offset + 1}–{offset + list.sessions.length} of {list.total}
            </span>
            <button
              type="button"
              disabled={offset + PAGE >= list.total}
              onClick={() => setOffset(offset + PAGE)}
            >
              Older
            </button>
          </div>
        </>
      )}
    </div>
  );
}
