// The dashboard shell: login gate, the live connection (kept for the whole login so switching
// pages never loses the flight state), theme, navigation.
import { useCallback, useEffect, useMemo, useReducer, useRef, useState } from 'react';
import { Api, ApiFailure } from './api/http';
import { LiveConnection, liveUrl, type LinkStatus } from './api/live';
import {
  clearLogin,
  fromLoginResponse,
  loadLogin,
  saveLogin,
  type StoredLogin,
} from './logic/auth';
import { FrameBus, ViewBus } from './logic/frameBus';
import { initialLiveState, liveReducer } from './logic/liveState';
import { parseRoute, routeHash, type Route } from './logic/route';
import { playAlarm } from './logic/sound';
import type { Config, LoginResponse, WsClientMessage } from './types';
import { LoginPage } from './pages/LoginPage';
import { FlyPage } from './pages/FlyPage';
import { SessionsPage } from './pages/SessionsPage';
import { ReplayPage } from './pages/ReplayPage';
import { SettingsPage } from './pages/SettingsPage';
import { HelpPage } from './pages/HelpPage';

export type Theme = 'light' | 'dark';

function applyTheme(theme: Theme) {
  document.documentElement.dataset.theme = theme;
  document
    .querySelector('meta[name="theme-color"]')
    ?.setAttribute('content', theme === 'dark' ? '#0f172a' : '#f8fafc');
}

function useRoute(): [Route, (r: Route) => void] {
  const [route, setRoute] = useState(() => parseRoute(window.location.hash));
  useEffect(() => {
    const on = () => setRoute(parseRoute(window.location.hash));
    window.addEventListener('hashchange', on);
    return () => window.removeEventListener('hashchange', on);
  }, []);
  return [route, (r) => (window.location.hash = routeHash(r))];
}

export function App() {
  const [login, setLogin] = useState<StoredLogin | null>(() => loadLogin(localStorage, Date.now()));
  const [loginNotice, setLoginNotice] = useState<string | null>(null);
  const [route, go] = useRoute();
  const [theme, setTheme] = useState<Theme>(login?.user.theme ?? 'dark');
  const [config, setConfig] = useState<Config | null>(null);
  const [live, dispatch] = useReducer(liveReducer, initialLiveState);
  const [link, setLink] = useState<{ status: LinkStatus; detail?: string }>({ status: 'closed' });
  const frames = useMemo(() => new FrameBus(), []);
  const views = useMemo(() => new ViewBus(), []);
  const connRef = useRef<LiveConnection | null>(null);

  const endLogin = useCallback(
    (notice: string | null) => {
      connRef.current?.stop();
      connRef.current = null;
      clearLogin(localStorage);
      setLogin(null);
      setConfig(null);
      setLoginNotice(notice);
      dispatch({ kind: 'reset' });
      frames.clear();
      views.clear();
    },
    [frames, views],
  );

  const api = useMemo(
    () =>
      new Api({
        onUnauthorized: (f: ApiFailure) =>
          endLogin(`${f.envelope.cause} ${f.envelope.suggestion}`.trim()),
      }),
    [endLogin],
  );
  api.setToken(login?.token ?? null);

  useEffect(() => applyTheme(theme), [theme]);

  // The live connection lives as long as the login.
  useEffect(() => {
    if (!login) return;
    const conn = new LiveConnection({
      url: liveUrl(login.token),
      expiresAtMs: login.expiresAtMs,
      onMessage: (msg) => {
        if (msg.type === 'frame') {
          frames.push(msg.data);
          return;
        }
        if (msg.type === 'picture') {
          frames.pictures.push(msg.data);
          return;
        }
        if (msg.type === 'drone_view') {
          views.push(msg.data);
          return;
        }
        if (msg.type === 'alert' && msg.data.severity === 'CRITICAL' && !msg.replay) playAlarm();
        dispatch({ kind: 'message', message: msg, nowMs: Date.now() });
      },
      onStatus: (status, detail) => setLink({ status, detail }),
      onAuthLost: (reason) => endLogin(reason),
      checkAuth: async () => {
        try {
          await api.getConfig();
          return true;
        } catch (e) {
          return !(e instanceof ApiFailure && e.status === 401);
        }
      },
    });
    connRef.current = conn;
    conn.start();
    return () => conn.stop();
  }, [login, api, endLogin, frames, views]);

  useEffect(() => {
    if (!login) return;
    const id = setInterval(() => dispatch({ kind: 'tick', nowMs: Date.now() }), 250);
    return () => clearInterval(id);
  }, [login]);

  useEffect(() => {
    if (!login) return;
    api
      .getConfig()
      .then((c) => {
        setConfig(c);
        setTheme(c.theme);
      })
      .catch(() => {});
  }, [login, api]);

  // For the end-to-end tests and for measuring: read-only counters.
  useEffect(() => {
    (window as unknown as { __gbdcs?: unknown }).__gbdcs = { frames, views, live, link };
  });

  const send = useCallback((m: WsClientMessage) => connRef.current?.send(m) ?? false, []);

  const onLoggedIn = (r: LoginResponse) => {
    const l = fromLoginResponse(r, Date.now());
    saveLogin(localStorage, l);
    setLoginNotice(null);
    setTheme(r.user.theme);
    setLogin(l);
    if (route.page !== 'fly') go({ page: 'fly' });
  };

  const logout = async () => {
    connRef.current?.stop(); // our own close first: the server's 4001 is then not needed
    try {
      await api.logout();
    } catch {
      // Logged out locally either way; the token dies at expiry.
    }
    endLogin('You logged out.');
  };

  if (!login) {
    return <LoginPage api={api} notice={loginNotice} onLoggedIn={onLoggedIn} />;
  }

  const nav: { route: Route; label: string }[] = [
    { route: { page: 'fly' }, label: 'Fly' },
    { route: { page: 'sessions' }, label: 'Sessions' },
    { route: { page: 'settings' }, label: 'Settings' },
    { route: { page: 'help' }, label: 'Help' },
  ];
  const current = route.page === 'replay' ? 'sessions' : route.page;

  return (
    <div className="app">
      <a className="skip" href="#main">
        Skip to content
      </a>
      <header className="topbar">
        <span className="brand" aria-hidden="true">
          GBDCS
        </span>
        <nav aria-label="Main">
          <ul>
            {nav.map((n) => (
              <li key={n.label}>
                <a
                  href={routeHash(n.route)}
                  aria-current={current === n.route.page ? 'page' : undefined}
                >
                  {n.label}
                </a>
              </li>
            ))}
          </ul>
        </nav>
        <span className={`link link-${link.status}`} role="status" aria-label="Server connection">
          {link.status === 'open' ? 'Live' : link.status}
        </span>
        <span className="user" title="Logged in as">
          {login.user.email}
        </span>
        <button type="button" onClick={() => void logout()}>
          Log out
        </button>
      </header>
      <main id="main" tabIndex={-1}>
        {route.page === 'fly' && (
          <FlyPage
            live={live}
            frames={frames}
            views={views}
            send={send}
            api={api}
            config={config}
            link={link}
            dispatch={dispatch}
          />
        )}
        {route.page === 'sessions' && <SessionsPage api={api} />}
        {route.page === 'replay' && (
          <ReplayPage api={api} sessionId={route.sessionId} config={config} />
        )}
        {route.page === 'settings' && (
          <SettingsPage
            api={api}
            config={config}
            theme={theme}
            onConfig={(c) => {
              setConfig(c);
              setTheme(c.theme);
            }}
          />
        )}
        {route.page === 'help' && <HelpPage config={config} />}
      </main>
    </div>
  );
}
