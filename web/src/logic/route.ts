// Hash routes (#/fly, #/sessions, #/sessions/12, #/settings, #/help): the server serves
// index.html for every path, and hash routes also work from a file or a phone's home screen.
export type Route =
  | { page: 'fly' }
  | { page: 'sessions' }
  | { page: 'replay'; sessionId: number }
  | { page: 'settings' }
  | { page: 'help' };

export function parseRoute(hash: string): Route {
  const h = hash.replace(/^#\/?/, '');
  const m = /^sessions\/(\d+)$/.exec(h);
  if (m) return { page: 'replay', sessionId: Number(m[1]) };
  if (h === 'sessions') return { page: 'sessions' };
  if (h === 'settings') return { page: 'settings' };
  if (h === 'help') return { page: 'help' };
  return { page: 'fly' };
}

export function routeHash(r: Route): string {
  return r.page === 'replay' ? `#/sessions/${r.sessionId}` : `#/${r.page}`;
}
