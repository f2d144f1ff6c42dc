export function App() {
  return (
    <main>
      <h1>GBDCS operator dashboard</h1>
    </main>
  );
}
