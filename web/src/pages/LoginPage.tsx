import { useState, type FormEvent } from 'react';
import { Api, ApiFailure } from '../api/http';
import { ErrorBox } from '../components/ErrorBox';
import type { LoginResponse } from '../types';

interface Props {
  api: Api;
  notice: string | null;
  onLoggedIn(r: LoginResponse): void;
}

export function LoginPage({ api, notice, onLoggedIn }: Props) {
  const [mode, setMode] = useState<'login' | 'register'>('login');
  const [email, setEmail] = useState('');
  const [password, setPassword] = useState('');
  const [busy, setBusy] = useState(false);
  const [failure, setFailure] = useState<ApiFailure | null>(null);
  const [info, setInfo] = useState<string | null>(null);

  const submit = async (ev: FormEvent) => {
    ev.preventDefault();
    setBusy(true);
    setFailure(null);
    setInfo(null);
    try {
      if (mode === 'register') {
        await api.register(email, password);
        setInfo('Account created. Logging you in…');
      }
      onLoggedIn(await api.login(email, password));
    } catch (e) {
      if (e instanceof ApiFailure) setFailure(e);
      else throw e;
    } finally {
      setBusy(false);
    }
  };

  return (
    <main className="login" id="main">
      <div className="login-card">
        <h1>GBDCS</h1>
        <p className="tagline">Gesture-based drone control: operator dashboard</p>
        {notice && (
          <p className="notice" role="status">
            {notice}
          </p>
        )}
        <div className="tabs" role="tablist" aria-label="Log in or register">
          <button
            type="button"
            role="tab"
            aria-selected={mode === 'login'}
            onClick={() => setMode('login')}
          >
            Log in
          </button>
          <button
            type="button"
            role="tab"
            aria-selected={mode === 'register'}
            onClick={() => setMode('register')}
          >
            Register
          </button>
        </div>
        <form
          onSubmit={(e) => void submit(e)}
          aria-label={mode === 'login' ? 'Log in' : 'Register'}
        >
          <label>
            E-mail
            <input
              type="email"
              name="email"
              autoComplete="username"
              required
              value={email}
              onChange={(e) => setEmail(e.target.value)}
            />
          </label>
          <label>
            Password
            <input
              type="password"
              name="password"
              autoComplete={mode === 'login' ? 'current-password' : 'new-password'}
              required
              value={password}
              onChange={(e) => setPassword(e.target.value)}
              aria-describedby={mode === 'register' ? 'pw-rule' : undefined}
            />
          </label>
          {mode === 'register' && (
            <p id="pw-rule" className="hint">
              At least 10 characters, and not your e-mail address.
            </p>
          )}
          <button type="submit" className="primary" disabled={busy}>
            {mode === 'login' ? 'Log in' : 'Create account'}
          </button>
        </form>
        {info && <p role="status">{info}</p>}
        <ErrorBox
          failure={failure}
          title={mode === 'login' ? 'Could not log in' : 'Could not register'}
        />
      </div>
    </main>
  );
}
